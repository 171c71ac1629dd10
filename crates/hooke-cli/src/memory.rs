//! The process's peak resident memory, for `hooke bench`: what a run of a scene costs in
//! memory beside its time, read where the system keeps it.

/// The peak resident set of this process so far, MiB: Linux's high-water mark (`VmHWM` in
/// `/proc/self/status`); `None` where there is none to read.
pub(crate) fn peak_resident_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    high_water_mark(&status)
}

/// `VmHWM` of a `/proc/<pid>/status` text, MiB.
fn high_water_mark(status: &str) -> Option<f64> {
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let mut words = line["VmHWM:".len()..].split_whitespace();
    let kib: f64 = words.next()?.parse().ok()?;
    (words.next()? == "kB").then_some(kib / 1024.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_high_water_mark_is_read_in_mib_and_nothing_else_is_taken_for_it() {
        let status = "Name:\thooke\nVmPeak:\t  200000 kB\nVmHWM:\t   65536 kB\nVmRSS:\t 1024 kB\n";
        assert_eq!(high_water_mark(status), Some(64.0));
        assert_eq!(high_water_mark("VmRSS:\t 1024 kB\n"), None);
        assert_eq!(high_water_mark("VmHWM:\t lots kB\n"), None);
        assert_eq!(high_water_mark("VmHWM:\t 1024 pages\n"), None);
    }

    /// On Linux the mark is there and grows with what the process touches.
    #[cfg(target_os = "linux")]
    #[test]
    fn the_mark_covers_memory_the_process_touched() {
        let before = peak_resident_mib().expect("Linux keeps VmHWM");
        let touched = vec![1u8; 64 << 20];
        let after = peak_resident_mib().expect("Linux keeps VmHWM");
        assert!(touched.iter().map(|&b| b as usize).sum::<usize>() == 64 << 20);
        assert!(after >= before.max(64.0), "{before} -> {after}");
    }
}
