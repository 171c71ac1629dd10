//! Helpers the `hooke` binary's test files share: running it in a scratch folder, reading
//! what it printed, interrupting it, waiting for its files.

// Each test file uses its own subset.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

/// `hooke` with `dir` as its working folder.
pub fn hooke_in(dir: &Path) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_hooke"));
    c.current_dir(dir);
    c
}

/// Runs `hooke ARGS` in `dir` to the end.
pub fn hooke(args: &[&str], dir: &Path) -> Output {
    hooke_in(dir).args(args).output().unwrap()
}

/// Starts `hooke ARGS` in `dir`, its output piped.
pub fn spawn(args: &[&str], dir: &Path) -> Child {
    hooke_in(dir)
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// The workspace root, found from this crate's manifest.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .canonicalize()
        .unwrap()
}

/// A fresh, empty folder for one test.
pub fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hooke-test-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The names of the files in `dir`.
pub fn file_names(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect()
}

/// What a finished command printed on stderr.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Sends SIGINT (what Ctrl-C sends) to `child`.
pub fn interrupt(child: &Child) {
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
}

/// Files under `dir` (recursively) whose names mark an unfinished write.
pub fn temporaries(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap().flatten() {
        let path = entry.path();
        if path.is_dir() {
            out.extend(temporaries(&path));
        } else if path.to_string_lossy().ends_with(".tmp") {
            out.push(path);
        }
    }
    out
}

/// Waits until `ready()`, or panics after five minutes: a hung process, not a slow machine
/// (the tests run on loaded machines, and nothing here depends on their speed).
pub fn wait_for(what: &str, mut ready: impl FnMut() -> bool) {
    let start = Instant::now();
    while !ready() {
        assert!(
            start.elapsed() < Duration::from_secs(300),
            "timed out waiting for {what}"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// A running `hooke` whose stderr is read as it comes, so that a test can wait for what it
/// says instead of sleeping.
pub struct Watched {
    /// The process.
    pub child: Child,
    said: std::sync::Arc<std::sync::Mutex<String>>,
    reader: Option<std::thread::JoinHandle<()>>,
}

impl Watched {
    /// Starts `hooke ARGS` in `dir`.
    pub fn spawn(args: &[&str], dir: &Path) -> Self {
        use std::io::Read;
        let mut child = spawn(args, dir);
        let mut err = child.stderr.take().unwrap();
        let said = std::sync::Arc::new(std::sync::Mutex::new(String::new()));
        let sink = said.clone();
        let reader = std::thread::spawn(move || {
            let mut buf = [0u8; 4096];
            while let Ok(n) = err.read(&mut buf) {
                if n == 0 {
                    break;
                }
                sink.lock()
                    .unwrap()
                    .push_str(&String::from_utf8_lossy(&buf[..n]));
            }
        });
        Self {
            child,
            said,
            reader: Some(reader),
        }
    }

    /// Waits until stderr holds `text`.
    pub fn wait_to_say(&self, text: &str) {
        wait_for(&format!("stderr to say {text:?}"), || {
            self.said.lock().unwrap().contains(text)
        });
    }

    /// Waits for the end: the exit status and all of stderr.
    pub fn finish(mut self) -> (std::process::ExitStatus, String) {
        let status = self.child.wait().unwrap();
        if let Some(r) = self.reader.take() {
            r.join().unwrap();
        }
        let said = self.said.lock().unwrap().clone();
        (status, said)
    }
}

/// How many files in `dir` end in `.ext` (none when it does not exist).
pub fn count_files(dir: &Path, ext: &str) -> usize {
    std::fs::read_dir(dir).map_or(0, |d| {
        d.flatten()
            .filter(|e| e.path().extension().is_some_and(|x| x == ext))
            .count()
    })
}

/// How many of `taken` frames, `seconds` of simulated time apart, a GIF shows: all when
/// they are two hundredths of a second apart or more, else the one nearest each slot of two
/// hundredths (the GIF plays in real time; `hooke::image_out::GifWriter`).
pub fn shown(taken: usize, seconds: f64) -> usize {
    let period = seconds * 100.0;
    if period >= 2.0 {
        return taken;
    }
    (0..)
        .take_while(|j| ((*j as f64) * 2.0 / period).round() < taken as f64)
        .count()
}

pub fn gif_frames(path: &Path) -> usize {
    use image::AnimationDecoder;
    let file = std::io::BufReader::new(std::fs::File::open(path).unwrap());
    image::codecs::gif::GifDecoder::new(file)
        .unwrap()
        .into_frames()
        .collect_frames()
        .unwrap()
        .len()
}
