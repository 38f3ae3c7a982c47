//! Watching a model's folder (`notify`) so the viewer reloads the model when it or a file beside
//! it (a `.bin`, a texture) changes on disk; changes are gathered until the folder has been
//! quiet for [`QUIET`], so an exporter writing several files reloads once.

use notify::{RecursiveMode, Watcher as _};
use std::path::Path;
use std::sync::mpsc::{channel, Receiver};
use std::time::{Duration, Instant};

/// How long the folder must be quiet after a change before the model is reloaded.
pub const QUIET: Duration = Duration::from_millis(200);

/// A watch on a model's folder.
pub struct Watch {
    _watcher: notify::RecommendedWatcher,
    events: Receiver<notify::Result<notify::Event>>,
    /// When the last change was seen, while one waits to be reported.
    pending: Option<Instant>,
}

impl Watch {
    /// Watches the folder holding `model` (not its subfolders).
    pub fn new(model: &Path) -> notify::Result<Self> {
        let folder = model
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        let (tx, events) = channel();
        let mut watcher = notify::recommended_watcher(move |e| {
            let _ = tx.send(e);
        })?;
        watcher.watch(folder, RecursiveMode::NonRecursive)?;
        Ok(Self {
            _watcher: watcher,
            events,
            pending: None,
        })
    }

    /// True once when files changed and the folder has since been quiet for [`QUIET`].
    pub fn changed(&mut self) -> bool {
        while let Ok(e) = self.events.try_recv() {
            if let Ok(e) = e {
                if e.kind.is_modify() || e.kind.is_create() || e.kind.is_remove() {
                    self.pending = Some(Instant::now());
                }
            }
        }
        match self.pending {
            Some(t) if t.elapsed() >= QUIET => {
                self.pending = None;
                true
            }
            _ => false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_written_file_is_reported_once_after_the_folder_is_quiet() {
        let dir = std::env::temp_dir().join(format!("umbra-watch-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let model = dir.join("m.gltf");
        std::fs::write(&model, "{}").unwrap();
        let mut w = Watch::new(&model).unwrap();
        assert!(!w.changed(), "nothing changed yet");
        std::fs::write(dir.join("m.bin"), [1u8, 2, 3]).unwrap();
        let start = Instant::now();
        let mut seen = false;
        while start.elapsed() < Duration::from_secs(10) && !seen {
            std::thread::sleep(Duration::from_millis(20));
            seen = w.changed();
        }
        assert!(seen, "the change was not reported within 10 s");
        assert!(
            start.elapsed() >= QUIET,
            "reported before the folder was quiet"
        );
        std::thread::sleep(QUIET * 2);
        assert!(!w.changed(), "reported twice");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
