//! The panel in the viewer: one UI pass per frame before drawing (its commands applied to this
//! very frame, exactly as the keys apply them) and scripted clicks on its widgets.

use super::keys::{AnimKey, KeyAction};
use super::App;
use crate::app::actions::Action;
use crate::app::panel::{panel, Command, PanelModel, Widgets};
use umbra::plan::effective_lights;
use winit::event_loop::ActiveEventLoop;

impl App {
    /// Runs the panel's pass (when it is shown) and applies what its widgets ask for.
    pub(super) fn run_panel(&mut self, el: &ActiveEventLoop) -> anyhow::Result<()> {
        let opts = &self.opts;
        let Some(s) = self.state.as_mut() else {
            return Ok(());
        };
        let Some(o) = s.overlay.as_mut().filter(|_| s.panel.open) else {
            return Ok(());
        };
        let model = PanelModel {
            scene: &opts.scene.name,
            view: &s.view,
            sun: s.sun,
            stats: &s.panel.stats,
            lights: effective_lights(&opts.scene.lights, &s.view).len(),
            cameras: opts
                .scene
                .cameras
                .iter()
                .map(|c| c.is_orthographic())
                .collect(),
            camera: s.camera_index,
            orthographic: s.controller.orthographic,
            animation: s.player.has_animations().then(|| s.player.label()),
            pick: s.panel.pick.as_deref(),
            tree: s.panel.tree.as_ref(),
            selected: s.panel.selected,
            status: s.panel.status.as_deref(),
            budget: s.budget_value,
        };
        let mut events = std::mem::take(&mut s.panel.events);
        // A scripted press is released on the pass after its own.
        if let Some(pos) = s.panel.release_due.take() {
            events.push(egui::Event::PointerButton {
                pos,
                button: egui::PointerButton::Primary,
                pressed: false,
                modifiers: Default::default(),
            });
        }
        let (mut commands, mut widgets) = (Vec::new(), Widgets::default());
        o.run(&s.window, events, |ui| {
            panel(ui, &model, &mut commands, &mut widgets)
        })?;
        s.panel.widgets = widgets;
        s.panel.release_due = s.panel.release.take();
        for c in commands {
            self.command(el, c);
        }
        Ok(())
    }

    /// Applies one of the panel's commands.
    fn command(&mut self, el: &ActiveEventLoop, c: Command) {
        let key = match c {
            Command::Set(a) => Some(KeyAction::Setting(a)),
            Command::ToggleShadows => Some(KeyAction::Setting(Action::ToggleShadows)),
            Command::ToggleDepthFit => Some(KeyAction::Setting(Action::ToggleDepthFit)),
            Command::ToggleSoft => Some(KeyAction::Setting(Action::ToggleSoft)),
            Command::Frame => Some(KeyAction::Frame),
            Command::ToggleOrthographic => Some(KeyAction::ToggleOrthographic),
            Command::ToggleFly => Some(KeyAction::ToggleFly),
            Command::PlayPause => Some(KeyAction::Anim(AnimKey::Toggle)),
            Command::Step(n) => Some(KeyAction::Anim(AnimKey::Step(n))),
            Command::NextAnimation => Some(KeyAction::Anim(AnimKey::Next)),
            Command::Screenshot => Some(KeyAction::Screenshot),
            _ => None,
        };
        if let Some(k) = key {
            self.act(el, k);
            return;
        }
        match c {
            Command::ShadowLight(i) => {
                if let Some(s) = self.state.as_mut() {
                    s.view.shown_light = i;
                    match i {
                        Some(i) => println!(
                            "shadow view: light {i} (the first shadowed light if it casts none)"
                        ),
                        None => println!("shadow view: the first shadowed light"),
                    }
                }
            }
            Command::Camera(i) => self.use_camera(i),
            Command::SelectNode(i) => self.select_node(i),
            Command::Budget(b) => {
                if let Some(s) = self.state.as_mut() {
                    s.budget_value = b;
                    match b {
                        Some(b) => println!("shadow budget: {b} %"),
                        None => println!("shadow budget: off"),
                    }
                }
                self.restart_budget();
            }
            _ => {}
        }
    }

    /// Selects node `i` of the tree: frames what it places and tints its first primitive.
    fn select_node(&mut self, i: usize) {
        let opts = &self.opts;
        let Some(s) = self.state.as_mut() else { return };
        s.panel.selected = Some(i);
        let Some((bounds, first)) = s.panel.tree.as_ref().and_then(|t| t.bounds(i, &opts.scene))
        else {
            println!("node {i}: places nothing to frame");
            return;
        };
        s.camera_index = None;
        let size = s.window.inner_size();
        let aspect = size.width.max(1) as f32 / size.height.max(1) as f32;
        s.controller.frame(&bounds, aspect);
        s.view.highlight = Some(first);
        println!("node {i}: selected and framed");
    }

    /// A scripted click on the panel's widget `name`: the pointer moves to its centre and
    /// presses now, and releases on the next pass (egui sees a real click).
    pub(super) fn click_widget(&mut self, name: &str) -> anyhow::Result<()> {
        let Some(s) = self.state.as_mut() else {
            return Ok(());
        };
        if !s.panel.open {
            anyhow::bail!("script: ui:{name}: the panel is hidden");
        }
        let Some(rect) = s.panel.widgets.0.get(name) else {
            let mut names: Vec<&String> = s.panel.widgets.0.keys().collect();
            names.sort();
            anyhow::bail!("script: ui:{name}: no such widget on the panel (it shows {names:?})");
        };
        let pos = rect.center();
        s.panel.events.push(egui::Event::PointerMoved(pos));
        s.panel.events.push(egui::Event::PointerButton {
            pos,
            button: egui::PointerButton::Primary,
            pressed: true,
            modifiers: Default::default(),
        });
        s.panel.release = Some(pos);
        Ok(())
    }
}
