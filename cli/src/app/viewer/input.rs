//! Input: keys, mouse buttons, the wheel, picking, the scene's cameras.

use super::*;
use crate::app::actions::{apply, next_shadow_light};
use crate::app::controller::{Button, Controller, Input};
use keys::{key_action, AnimKey, KeyAction};
use umbra::plan::effective_lights;
use winit::event::{ElementState, MouseButton};
use winit::event_loop::ActiveEventLoop;
use winit::keyboard::KeyCode;

impl App {
    /// Picks at window position (`x`, `y`): reports what is there (printed and in the panel)
    /// and highlights its primitive (nothing there: clears the highlight).
    #[cfg(feature = "reference")]
    pub(super) fn pick(&mut self, x: f32, y: f32) {
        let Some(s) = self.state.as_mut() else { return };
        let size = s.window.inner_size();
        let (w, h) = (size.width, size.height);
        if w == 0 || h == 0 || x >= w as f32 || y >= h as f32 {
            println!("pick: ({x:.0}, {y:.0}) is outside the {w}x{h} window");
            return;
        }
        let scene = &self.opts.scene;
        let result = (|| -> anyhow::Result<String> {
            if s.pick_renderer.is_none() {
                s.pick_renderer = Some(umbra::render::Renderer::with_options(
                    &s.ctx,
                    scene,
                    &self.opts.scene_options,
                )?);
            }
            let r = s.pick_renderer.as_mut().expect("created above");
            let mut v = s.view.clone();
            v.mode = umbra::plan::ViewMode::Shadow;
            v.highlight = None;
            let frame = r.render(&v, w, h)?;
            let reference = umbra_lab::reference::ReferenceScene::new(scene);
            // Continuous window coordinates: pixel (i, j) spans [i, i + 1) × [j, j + 1).
            let pick = reference.pick(&frame.plan, x, y, w, h);
            let gpu = frame.image.get_pixel(x as u32, y as u32)[0] as f32 / 255.0;
            s.view.highlight = pick.as_ref().map(|p| (p.instance, p.primitive));
            Ok(crate::app::pick::describe(
                scene,
                &frame.plan,
                (x, y),
                pick.as_ref(),
                Some(gpu),
            ))
        })();
        let line = result.unwrap_or_else(|e| format!("pick: failed: {e:#}"));
        println!("{line}");
        s.panel.pick = Some(line);
    }

    #[cfg(not(feature = "reference"))]
    pub(super) fn pick(&mut self, x: f32, y: f32) {
        let line = format!(
            "pick: ({x:.0}, {y:.0}): picking needs umbra built with the `reference` feature"
        );
        println!("{line}");
        if let Some(s) = self.state.as_mut() {
            s.panel.pick = Some(line);
        }
    }

    pub(super) fn wheel(&mut self, lines: f32) {
        if let Some(s) = self.state.as_mut() {
            s.camera_index = None;
            s.controller.handle(Input::Scroll(lines));
        }
    }

    pub(super) fn key(&mut self, el: &ActiveEventLoop, code: KeyCode, pressed: bool) {
        let Some(action) = key_action(code) else {
            return;
        };
        match action {
            KeyAction::Move(k) => {
                if let Some(s) = self.state.as_mut() {
                    s.controller.handle(Input::Key(k, pressed));
                }
            }
            _ if !pressed => {}
            a => self.act(el, a),
        }
    }

    /// Does what a key (or the panel's widget for it) does.
    pub(super) fn act(&mut self, el: &ActiveEventLoop, action: KeyAction) {
        let opts = &self.opts;
        let Some(s) = self.state.as_mut() else { return };
        match action {
            KeyAction::Move(_) => {}
            KeyAction::Setting(a) => println!("{}", apply(a, &mut s.view, &mut s.sun)),
            KeyAction::ShadowLight => {
                let n = effective_lights(&opts.scene.lights, &s.view).len();
                println!("{}", next_shadow_light(&mut s.view, n));
            }
            KeyAction::Frame => {
                s.camera_index = None;
                let size = s.window.inner_size();
                s.controller.frame(
                    &s.bounds,
                    size.width.max(1) as f32 / size.height.max(1) as f32,
                );
                println!("camera: framing the scene");
            }
            KeyAction::ToggleFly => {
                s.camera_index = None;
                s.controller.toggle_mode();
                println!("camera: {:?}", s.controller.mode);
            }
            KeyAction::NextCamera => {
                if opts.scene.cameras.is_empty() {
                    println!("camera: the scene has no cameras");
                } else {
                    let i = s
                        .camera_index
                        .map(|i| (i + 1) % opts.scene.cameras.len())
                        .unwrap_or(0);
                    self.use_camera(Some(i));
                }
            }
            KeyAction::ToggleOrthographic => {
                if let Some(i) = s.camera_index.take() {
                    // Continue from the glTF camera on screen.
                    s.controller = Controller::from_camera(&opts.scene.cameras[i], &s.bounds);
                }
                s.controller.toggle_projection();
                let kind = if s.controller.orthographic {
                    "orthographic"
                } else {
                    "perspective"
                };
                println!("camera: {kind}");
            }
            KeyAction::Screenshot => s.want_screenshot = true,
            KeyAction::Anim(k) => {
                let p = &mut s.player;
                let line = match k {
                    AnimKey::Toggle => p.toggle(),
                    AnimKey::Step(n) => p.step(n),
                    AnimKey::Speed(f) => p.scale_speed(f),
                    AnimKey::Next => p.next_animation(),
                };
                s.pose_dirty = true;
                println!("{line}");
            }
            KeyAction::TogglePanel => {
                s.panel.open = !s.panel.open && s.overlay.is_some();
                if let Some(o) = s.overlay.as_mut() {
                    o.clear();
                }
                println!("panel: {}", if s.panel.open { "shown" } else { "hidden" });
            }
            KeyAction::Quit => el.exit(),
        }
    }

    /// Looks through glTF camera `i` (None: back to the viewer's own camera).
    pub(super) fn use_camera(&mut self, i: Option<usize>) {
        let opts = &self.opts;
        let Some(s) = self.state.as_mut() else { return };
        s.camera_index = i.filter(|&i| i < opts.scene.cameras.len());
        match s.camera_index {
            Some(i) => {
                s.view.camera = opts.scene.cameras[i];
                s.controller = Controller::from_camera(&s.view.camera, &s.bounds);
                let kind = if s.view.camera.is_orthographic() {
                    "orthographic"
                } else {
                    "perspective"
                };
                println!("camera: glTF camera {i} ({kind})");
            }
            None => println!("camera: the viewer's"),
        }
    }

    /// A mouse button: a left click that does not move the cursor (3 px) picks; buttons drive
    /// the camera controller.
    pub(super) fn mouse(&mut self, state: ElementState, button: MouseButton) {
        let b = match button {
            MouseButton::Left => Some(Button::Left),
            MouseButton::Right => Some(Button::Right),
            MouseButton::Middle => Some(Button::Middle),
            _ => None,
        };
        let mut click = None;
        if let (Some(Button::Left), Some(s)) = (b, self.state.as_mut()) {
            if state == ElementState::Pressed {
                s.press_at = Some(s.cursor);
            } else if let Some((px, py)) = s.press_at.take() {
                let (cx, cy) = s.cursor;
                if (cx - px).abs() <= 3.0 && (cy - py).abs() <= 3.0 {
                    click = Some((cx, cy));
                }
            }
        }
        if let Some((x, y)) = click {
            self.pick(x, y);
        }
        if let (Some(b), Some(s)) = (b, self.state.as_mut()) {
            if s.camera_index.take().is_some() {
                s.controller = Controller::from_camera(&s.view.camera, &s.bounds);
            }
            s.controller.handle(if state == ElementState::Pressed {
                Input::Press(b)
            } else {
                Input::Release(b)
            });
        }
    }
}
