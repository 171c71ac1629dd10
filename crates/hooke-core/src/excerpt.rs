//! Short quotes of user input for error messages, so a 10 MB line does not become a 10 MB
//! message.

/// At most `max_chars` characters of `text`, with `…` where it was cut.
///
/// ```
/// use hooke_core::excerpt;
/// assert_eq!(excerpt("1.5", 40), "1.5");
/// assert_eq!(excerpt("abcdef", 3), "abc…");
/// assert_eq!(excerpt("äöüß", 2), "äö…");
/// ```
pub fn excerpt(text: &str, max_chars: usize) -> String {
    match text.char_indices().nth(max_chars) {
        Some((cut, _)) => format!("{}…", &text[..cut]),
        None => text.to_string(),
    }
}
