//! What the viewer tests share: a private X server per test, the output folder, and running the
//! `umbra` binary with a display.

#![allow(dead_code)] // each test file uses its own part

use std::path::{Path, PathBuf};
use std::process::{Child, Command};

/// A private X server for one test; killed on drop.
pub struct Xvfb {
    child: Child,
    /// The display name (`:N`).
    pub display: String,
}

impl Xvfb {
    /// Starts a server on a free display.
    pub fn start() -> Xvfb {
        static NEXT: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
        let base = 100 + (std::process::id() % 200) * 4;
        for _ in 0..200 {
            let n = base + NEXT.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
            let lock = format!("/tmp/.X{n}-lock");
            if Path::new(&lock).exists() {
                continue;
            }
            let child = Command::new("Xvfb")
                .args([
                    format!(":{n}").as_str(),
                    "-screen",
                    "0",
                    "1280x1024x24",
                    "-nolisten",
                    "tcp",
                ])
                .stdout(std::process::Stdio::null())
                .stderr(std::process::Stdio::null())
                .spawn()
                .expect("Xvfb is needed for the viewer tests (apt-get install xvfb)");
            let socket = format!("/tmp/.X11-unix/X{n}");
            let mut child = child;
            for _ in 0..100 {
                if child.try_wait().ok().flatten().is_some() {
                    break; // this display was taken: try the next
                }
                if Path::new(&socket).exists() {
                    std::thread::sleep(std::time::Duration::from_millis(100));
                    if child.try_wait().ok().flatten().is_none() {
                        return Xvfb {
                            child,
                            display: format!(":{n}"),
                        };
                    }
                    break;
                }
                std::thread::sleep(std::time::Duration::from_millis(50));
            }
            let _ = child.kill();
            let _ = child.wait();
        }
        panic!("could not start Xvfb");
    }
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// A file in the tests' output folder.
pub fn out(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("umbra-test-output");
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

/// Runs `umbra ARGS` on `display`: (success, stdout and stderr).
pub fn umbra(args: &[&str], display: Option<&str>) -> (bool, String) {
    let mut c = Command::new(env!("CARGO_BIN_EXE_umbra"));
    c.args(args).env_remove("WAYLAND_DISPLAY");
    if let Some(d) = display {
        c.env("DISPLAY", d);
    }
    let o = c.output().unwrap();
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    (o.status.success(), text)
}
