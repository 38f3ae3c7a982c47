//! Opening a dropped file and reloading the model when it changes on disk: the new scene
//! replaces the old in the same window (the camera kept on a reload, the new model framed when
//! another file is opened); a file that fails to load leaves the previous scene on screen and
//! its one-line error in the panel.

use super::{framing_bounds, App};
use crate::app::scene_tree::SceneTree;
use std::path::Path;
use umbra::scene::Scene;

/// The scene tree of the glTF file at `path`, loaded as `scene` (None when it cannot be read).
pub(super) fn tree_of(path: &Path, scene: &Scene) -> Option<SceneTree> {
    umbra::scene::inspect::document_report(path, scene)
        .ok()
        .map(|r| SceneTree::from_report(&r))
}

impl App {
    /// Reloads the model when its folder changed on disk (and was quiet since).
    pub(super) fn reload_if_changed(&mut self) {
        let changed = self
            .state
            .as_mut()
            .and_then(|s| s.watch.as_mut())
            .is_some_and(|w| w.changed());
        if let (true, Some(path)) = (changed, self.opts.path.clone()) {
            self.open(&path, false);
        }
    }

    /// Loads `path` and shows it in place of the current scene; `new_file`: another file than
    /// the one shown (it is then watched, and framed), else a reload keeping the camera.
    pub(super) fn open(&mut self, path: &Path, new_file: bool) {
        let loaded = (self.opts.loader)(path);
        let Some(s) = self.state.as_mut() else { return };
        let scene = match loaded {
            Ok(scene) => scene,
            Err(e) => {
                let line = format!(
                    "load: {}: {e:#}; keeping {}",
                    path.display(),
                    self.opts.scene.name
                );
                println!("{line}");
                s.panel.status = Some(line);
                return;
            }
        };
        if let Err(e) = s.renderer.set_scene(&scene, &self.opts.scene_options) {
            let line = format!("load: {}: cannot upload it: {e}", path.display());
            println!("{line}");
            s.panel.status = Some(line);
            return;
        }
        #[cfg(feature = "reference")]
        {
            s.pick_renderer = None;
        }
        s.view.highlight = None;
        s.panel.pick = None;
        s.panel.selected = None;
        s.panel.tree = tree_of(path, &scene);
        s.bounds = framing_bounds(&scene);
        s.player = crate::app::player::Player::new(scene.rig.as_deref(), None);
        s.pose_dirty = s.player.has_animations();
        if s.camera_index.is_some_and(|i| i >= scene.cameras.len()) {
            s.camera_index = None;
        }
        if new_file {
            s.camera_index = None;
            let size = s.window.inner_size();
            let aspect = size.width.max(1) as f32 / size.height.max(1) as f32;
            s.controller.frame(&s.bounds, aspect);
            s.watch = crate::app::reload::Watch::new(path)
                .map_err(|e| eprintln!("warning: {}: not watched: {e}", path.display()))
                .ok();
            self.opts.path = Some(path.to_path_buf());
        }
        s.reloads += 1;
        let line = format!(
            "{}: {} ({} triangles)",
            if new_file { "opened" } else { "reloaded" },
            path.display(),
            s.renderer.triangles()
        );
        println!("{line}");
        s.panel.status = Some(line);
        s.window.set_title(&format!("umbra — {}", scene.name));
        self.opts.scene = scene;
        self.restart_budget();
    }

    /// Restarts the budget worker on the current scene (after a load, or a new budget).
    pub(super) fn restart_budget(&mut self) {
        #[cfg(feature = "sweep")]
        {
            let Some(s) = self.state.as_mut() else { return };
            if let Some(b) = s.budget.take() {
                match b.finish() {
                    Ok(n) => s.worker_problems += n,
                    Err(e) => eprintln!("warning: budget worker: {e:#}"),
                }
            }
            s.budget = s.budget_value.map(|b| {
                crate::app::budget_worker::BudgetWorker::start(
                    self.opts.scene.clone(),
                    b,
                    self.opts.device.clone(),
                    self.opts.validation,
                )
            });
        }
    }
}
