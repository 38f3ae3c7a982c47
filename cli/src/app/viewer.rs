//! `umbra view`: the real-time viewer (winit). Same passes as the offscreen path; orbit/fly
//! cameras; keys change the light and shadow settings and print what changed; frame statistics
//! in the title a few times a second; `P` saves a screenshot of what is on screen.
//!
//! Keys: mouse left-drag rotate, right/middle-drag pan, wheel zoom, `F` frame the scene, `Tab`
//! orbit/fly (WASD, Q/E down/up, Shift faster), `C` next glTF camera, arrows rotate the sun,
//! `[`/`]` shadow-map size, `K` PCF kernel, `+`/`-` bias, `V` debug view, `H` shadows on/off,
//! `P` screenshot, `Esc` quit.

use super::actions::{apply, next_shadow_light, Action, SunAngles};
use super::controller::{Button, Controller, Input, MoveKey};
use super::script::ScriptStep;
use anyhow::{anyhow, Context as _};
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;
use umbra::gpu::{Context, ContextDesc, Validation};
use umbra::render::View;
use umbra::render::{effective_lights, surface_extensions, DrawResult, WindowRenderer};
use umbra::scene::{LightKind, Scene};
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::raw_window_handle::{HasDisplayHandle, HasWindowHandle};
use winit::window::{Window, WindowId};

/// How to run the viewer.
pub struct ViewerOptions {
    /// The scene.
    pub scene: Scene,
    /// Initial view (camera, sun, shadow settings, mode).
    pub view: View,
    /// Window inner size.
    pub size: (u32, u32),
    /// Upload options (texture filtering).
    pub scene_options: umbra::render::SceneOptions,
    /// FIFO presentation (vsync).
    pub vsync: bool,
    /// Render this many frames, then exit (with `screenshot`, save the last one).
    pub frames: Option<u64>,
    /// Where `--frames` saves the last frame.
    pub screenshot: Option<PathBuf>,
    /// Device name substring.
    pub device: Option<String>,
    /// Khronos validation on (exit 1 on any message).
    pub validation: bool,
    /// Inputs to play, one every few frames (automation, tests): `super::script`.
    pub script: Vec<ScriptStep>,
    /// Re-choose the shadow settings for this misclassification budget as the camera moves.
    pub shadow_budget: Option<f64>,
    /// Where the animation clock starts (`--animation`, `--time`: paused there); None: the
    /// first animation plays from 0.
    pub start: Option<(umbra::scene::anim::Playing, f32)>,
}

/// The animation keys.
#[derive(Clone, Copy)]
enum AnimKey {
    Toggle,
    Step(i32),
    Speed(f32),
    Next,
}

/// Frames between two script steps.
const SCRIPT_STEP_FRAMES: u64 = 2;
/// Frames after which resident memory is sampled for the end-of-run report.
const WARM_UP_FRAMES: u64 = 100;

/// Resident set size of this process in bytes (Linux; None elsewhere).
fn resident_bytes() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/statm").ok()?;
    let pages: u64 = s.split_whitespace().nth(1)?.parse().ok()?;
    Some(pages * 4096)
}

/// What a key does in the viewer.
enum KeyAction {
    Setting(Action),
    ShadowLight,
    Move(MoveKey),
    Frame,
    ToggleFly,
    NextCamera,
    ToggleOrthographic,
    Screenshot,
    Anim(AnimKey),
    Quit,
}

/// The key a script names (`super::script::KEYS`).
fn script_key(name: &str) -> Option<KeyCode> {
    Some(match name {
        "up" => KeyCode::ArrowUp,
        "down" => KeyCode::ArrowDown,
        "left" => KeyCode::ArrowLeft,
        "right" => KeyCode::ArrowRight,
        "[" => KeyCode::BracketLeft,
        "]" => KeyCode::BracketRight,
        "k" => KeyCode::KeyK,
        "+" => KeyCode::Equal,
        "-" => KeyCode::Minus,
        "v" => KeyCode::KeyV,
        "h" => KeyCode::KeyH,
        "n" => KeyCode::KeyN,
        "g" => KeyCode::KeyG,
        "j" => KeyCode::KeyJ,
        "l" => KeyCode::KeyL,
        "f" => KeyCode::KeyF,
        "tab" => KeyCode::Tab,
        "c" => KeyCode::KeyC,
        "p" => KeyCode::KeyP,
        "t" => KeyCode::KeyT,
        "comma" => KeyCode::Comma,
        "period" => KeyCode::Period,
        "space" => KeyCode::Space,
        "u" => KeyCode::KeyU,
        "i" => KeyCode::KeyI,
        "o" => KeyCode::KeyO,
        "z" => KeyCode::KeyZ,
        "x" => KeyCode::KeyX,
        "r" => KeyCode::KeyR,
        _ => return None,
    })
}

fn key_action(code: KeyCode) -> Option<KeyAction> {
    use KeyAction::*;
    Some(match code {
        KeyCode::ArrowLeft => Setting(Action::SunLeft),
        KeyCode::ArrowRight => Setting(Action::SunRight),
        KeyCode::ArrowUp => Setting(Action::SunUp),
        KeyCode::ArrowDown => Setting(Action::SunDown),
        KeyCode::BracketLeft => Setting(Action::MapSmaller),
        KeyCode::BracketRight => Setting(Action::MapLarger),
        KeyCode::KeyK => Setting(Action::CyclePcf),
        KeyCode::Equal | KeyCode::NumpadAdd => Setting(Action::BiasUp),
        KeyCode::Minus | KeyCode::NumpadSubtract => Setting(Action::BiasDown),
        KeyCode::KeyV => Setting(Action::CycleView),
        KeyCode::KeyH => Setting(Action::ToggleShadows),
        KeyCode::KeyN => Setting(Action::CycleCascades),
        KeyCode::KeyG => Setting(Action::ToggleDepthFit),
        KeyCode::KeyJ => Setting(Action::ToggleSoft),
        KeyCode::KeyT => Setting(Action::CycleTonemap),
        KeyCode::Period => Setting(Action::ExposureUp),
        KeyCode::Comma => Setting(Action::ExposureDown),
        KeyCode::KeyL => ShadowLight,
        KeyCode::KeyW => Move(MoveKey::W),
        KeyCode::KeyA => Move(MoveKey::A),
        KeyCode::KeyS => Move(MoveKey::S),
        KeyCode::KeyD => Move(MoveKey::D),
        KeyCode::KeyQ => Move(MoveKey::Q),
        KeyCode::KeyE => Move(MoveKey::E),
        KeyCode::ShiftLeft | KeyCode::ShiftRight => Move(MoveKey::Shift),
        KeyCode::KeyF => Frame,
        KeyCode::Tab => ToggleFly,
        KeyCode::KeyC => NextCamera,
        KeyCode::KeyO => ToggleOrthographic,
        KeyCode::KeyP => Screenshot,
        KeyCode::Space => Anim(AnimKey::Toggle),
        KeyCode::KeyU => Anim(AnimKey::Step(-1)),
        KeyCode::KeyI => Anim(AnimKey::Step(1)),
        KeyCode::KeyZ => Anim(AnimKey::Speed(0.5)),
        KeyCode::KeyX => Anim(AnimKey::Speed(2.0)),
        KeyCode::KeyR => Anim(AnimKey::Next),
        KeyCode::Escape => Quit,
        _ => return None,
    })
}

struct State {
    // Field order is drop order: the renderer (swapchain, surface) before the window.
    renderer: WindowRenderer,
    /// Offscreen renderer of the same scene for reading the GPU's shadow verdict at a picked
    /// pixel (created at the first pick).
    #[cfg(feature = "reference")]
    pick_renderer: Option<umbra::render::Renderer>,
    /// Cursor position, and where the left button went down (a click picks, a drag orbits).
    cursor: (f32, f32),
    press_at: Option<(f32, f32)>,
    ctx: Arc<Context>,
    window: Arc<Window>,
    controller: Controller,
    bounds: umbra::math::Aabb,
    view: View,
    sun: SunAngles,
    camera_index: Option<usize>,
    drawn: u64,
    /// Resident memory (bytes) after the warm-up frames, for the end-of-run report.
    rss_warm: Option<u64>,
    ticks: u64,
    first_draw: Option<Instant>,
    last_frame: Instant,
    last_title: Instant,
    frame_ms: Vec<f64>,
    cpu_ms: Vec<f64>,
    want_screenshot: bool,
    screenshot_count: u32,
    script_pos: usize,
    minimized: bool,
    /// The animation clock, and whether the scene must be posed anew before the next frame.
    player: super::player::Player,
    pose_dirty: bool,
    #[cfg(feature = "sweep")]
    budget: Option<super::budget_worker::BudgetWorker>,
}

struct App {
    opts: ViewerOptions,
    state: Option<State>,
    error: Option<anyhow::Error>,
}

impl App {
    fn fail(&mut self, el: &ActiveEventLoop, e: anyhow::Error) {
        if self.error.is_none() {
            self.error = Some(e);
        }
        el.exit();
    }

    fn init(&mut self, el: &ActiveEventLoop) -> anyhow::Result<State> {
        #[cfg(not(feature = "sweep"))]
        if self.opts.shadow_budget.is_some() {
            anyhow::bail!("--shadow-budget needs umbra built with the `sweep` feature");
        }
        let (w, h) = self.opts.size;
        let attrs = Window::default_attributes()
            .with_title(format!("umbra — {}", self.opts.scene.name))
            .with_inner_size(PhysicalSize::new(w, h));
        let window = Arc::new(el.create_window(attrs).context("cannot create a window")?);
        let display = window
            .display_handle()
            .map_err(|e| anyhow!("no display handle: {e}"))?
            .as_raw();
        let instance_extensions = surface_extensions(display)?;
        let ctx = Context::new(&ContextDesc {
            validation: if self.opts.validation {
                Validation::Required
            } else {
                Validation::Off
            },
            device: self.opts.device.clone(),
            instance_extensions,
            swapchain: true,
            pipeline_cache: super::pipeline_cache_path(),
            ..Default::default()
        })?;
        let handle = window
            .window_handle()
            .map_err(|e| anyhow!("no window handle: {e}"))?
            .as_raw();
        let size = window.inner_size();
        let renderer = WindowRenderer::new(
            &ctx,
            &self.opts.scene,
            (display, handle),
            (size.width, size.height),
            self.opts.vsync,
            &self.opts.scene_options,
        )?;
        let view = self.opts.view.clone();
        // What the camera frames and scales its speeds by (the model, not a helper ground).
        let bounds = self
            .opts
            .scene
            .framing
            .unwrap_or_else(|| self.opts.scene.bounds());
        let controller = Controller::from_camera(&view.camera, &bounds);
        let lights = effective_lights(&self.opts.scene.lights, &view);
        let sun_dir = lights
            .iter()
            .find(|l| l.kind == LightKind::Directional)
            .map(|l| l.direction)
            .unwrap_or(glam::Vec3::NEG_Y);
        println!(
            "viewer: {} on {} ({} triangles); press Esc to quit",
            self.opts.scene.name,
            ctx.device_name,
            renderer.triangles()
        );
        Ok(State {
            renderer,
            #[cfg(feature = "reference")]
            pick_renderer: None,
            cursor: (0.0, 0.0),
            press_at: None,
            ctx,
            window,
            controller,
            bounds,
            view,
            sun: SunAngles::from_direction(sun_dir),
            camera_index: None,
            drawn: 0,
            rss_warm: None,
            ticks: 0,
            first_draw: None,
            last_frame: Instant::now(),
            last_title: Instant::now(),
            frame_ms: Vec::new(),
            cpu_ms: Vec::new(),
            want_screenshot: false,
            screenshot_count: 0,
            script_pos: 0,
            minimized: size.width == 0 || size.height == 0,
            player: super::player::Player::new(
                self.opts.scene.rig.as_deref(),
                self.opts.start.clone(),
            ),
            pose_dirty: false,
            #[cfg(feature = "sweep")]
            budget: self.opts.shadow_budget.map(|b| {
                super::budget_worker::BudgetWorker::start(
                    self.opts.scene.clone(),
                    b,
                    self.opts.device.clone(),
                    self.opts.validation,
                )
            }),
        })
    }

    /// Runs the input script's next step when it is due (one every `SCRIPT_STEP_FRAMES` frames).
    fn script_step(&mut self, el: &ActiveEventLoop) -> anyhow::Result<()> {
        // Input script (automation): one step every few frames.
        let step = {
            let Some(s) = self.state.as_mut() else {
                return Ok(());
            };
            s.ticks += 1;
            let due = s.ticks % SCRIPT_STEP_FRAMES == 0 && s.script_pos < self.opts.script.len();
            due.then(|| {
                s.script_pos += 1;
                self.opts.script[s.script_pos - 1]
            })
        };
        if let Some(step) = step {
            let s = self.state.as_mut().expect("state");
            match step {
                ScriptStep::Resize(0, _) | ScriptStep::Resize(_, 0) => {
                    // What a minimised window reports on platforms that do: a 0×0 resize.
                    s.minimized = true;
                    s.renderer.resize(0, 0)?;
                }
                ScriptStep::Resize(w, h) => {
                    s.minimized = false;
                    let now = s
                        .window
                        .request_inner_size(PhysicalSize::new(w, h))
                        .unwrap_or_else(|| s.window.inner_size());
                    s.renderer.resize(now.width, now.height)?;
                }
                ScriptStep::Key(name) => {
                    if let Some(code) = script_key(name) {
                        self.key(el, code, true);
                        self.key(el, code, false);
                    }
                }
                ScriptStep::Wheel(lines) => self.wheel(lines),
                ScriptStep::Click(x, y) => self.pick(x, y),
            }
        }
        Ok(())
    }

    fn redraw(&mut self, el: &ActiveEventLoop) -> anyhow::Result<()> {
        self.script_step(el)?;
        let Some(s) = self.state.as_mut() else {
            return Ok(());
        };
        let now = Instant::now();
        let dt = (now - s.last_frame).as_secs_f32().min(0.25);
        s.last_frame = now;
        // The animation: wall time, or one frame step per frame in a run of --frames (so what
        // it draws does not depend on the machine's speed). Posing counts as CPU time.
        let clock = if self.opts.frames.is_some() {
            super::player::FRAME_STEP
        } else {
            dt
        };
        s.pose_dirty |= s.player.advance(clock);
        let mut pose_ms = 0.0;
        if std::mem::take(&mut s.pose_dirty) {
            let t0 = Instant::now();
            self.opts.scene.pose_at(&s.player.playing, s.player.time);
            s.renderer.set_pose(&self.opts.scene)?;
            #[cfg(feature = "reference")]
            if let Some(r) = s.pick_renderer.as_mut() {
                r.set_pose(&self.opts.scene)?;
            }
            pose_ms = t0.elapsed().as_secs_f64() * 1e3;
        }
        let opts = &self.opts;
        s.controller.update(dt);
        if s.camera_index.is_none() {
            s.view.camera = s.controller.camera();
        }
        #[cfg(feature = "sweep")]
        if let Some(b) = s.budget.as_mut() {
            let size = s.window.inner_size();
            b.request(&s.view, (size.width, size.height));
            // A run of a fixed number of frames (automation) waits for each choice, so what it
            // draws and prints does not depend on the machine's speed.
            if let Some(out) = b.poll(&mut s.view, opts.frames.is_some())? {
                let label = umbra_lab::analysis::chart::short_label_of(&out.choice.chosen.config);
                let line = super::cli::budget_line(&out.choice, &label);
                if out.kept {
                    println!("{line}; keeping the running settings (within budget here)");
                } else {
                    println!("{line}");
                }
            }
        }
        let last_scripted = s.script_pos >= opts.script.len();
        let final_frame = opts.frames.is_some_and(|n| s.drawn + 1 >= n) && last_scripted;
        let shot = s.want_screenshot || (final_frame && opts.screenshot.is_some());
        let t0 = Instant::now();
        let result = if s.minimized {
            DrawResult::Skipped
        } else {
            s.renderer.draw(&s.view, shot)?
        };
        let cpu = t0.elapsed().as_secs_f64() * 1e3 + pose_ms;
        if let DrawResult::Drawn { screenshot, .. } = result {
            s.drawn += 1;
            if s.drawn == WARM_UP_FRAMES {
                s.rss_warm = resident_bytes();
            }
            s.first_draw.get_or_insert(t0);
            s.cpu_ms.push(cpu);
            s.frame_ms.push(dt as f64 * 1e3);
            if let Some(img) = screenshot {
                save_screenshot(s, opts, &img, final_frame)?;
                s.want_screenshot = false;
            }
        }
        update_title(s, opts);
        if final_frame && s.drawn >= opts.frames.unwrap_or(0) {
            el.exit();
        }
        Ok(())
    }

    /// Picks at window position (`x`, `y`): prints what is there and highlights its primitive
    /// (nothing there: clears the highlight).
    #[cfg(feature = "reference")]
    fn pick(&mut self, x: f32, y: f32) {
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
            v.mode = umbra::render::ViewMode::Shadow;
            v.highlight = None;
            let frame = r.render(&v, w, h)?;
            let reference = umbra_lab::reference::ReferenceScene::new(scene);
            // Continuous window coordinates: pixel (i, j) spans [i, i + 1) × [j, j + 1).
            let pick = reference.pick(&frame.plan, x, y, w, h);
            let gpu = frame.image.get_pixel(x as u32, y as u32)[0] as f32 / 255.0;
            s.view.highlight = pick.as_ref().map(|p| (p.instance, p.primitive));
            Ok(super::pick::describe(
                scene,
                &frame.plan,
                (x, y),
                pick.as_ref(),
                Some(gpu),
            ))
        })();
        match result {
            Ok(line) => println!("{line}"),
            Err(e) => println!("pick: failed: {e:#}"),
        }
    }

    #[cfg(not(feature = "reference"))]
    fn pick(&mut self, x: f32, y: f32) {
        println!("pick: ({x:.0}, {y:.0}): picking needs umbra built with the `reference` feature");
    }

    fn wheel(&mut self, lines: f32) {
        if let Some(s) = self.state.as_mut() {
            s.camera_index = None;
            s.controller.handle(Input::Scroll(lines));
        }
    }

    fn key(&mut self, el: &ActiveEventLoop, code: KeyCode, pressed: bool) {
        let opts = &self.opts;
        let Some(s) = self.state.as_mut() else { return };
        let Some(action) = key_action(code) else {
            return;
        };
        match action {
            KeyAction::Move(k) => s.controller.handle(Input::Key(k, pressed)),
            _ if !pressed => {}
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
                    s.camera_index = Some(i);
                    s.view.camera = opts.scene.cameras[i];
                    s.controller = Controller::from_camera(&s.view.camera, &s.bounds);
                    let kind = if s.view.camera.is_orthographic() {
                        "orthographic"
                    } else {
                        "perspective"
                    };
                    println!("camera: glTF camera {i} ({kind})");
                }
            }
            KeyAction::ToggleOrthographic => {
                if let Some(i) = s.camera_index.take() {
                    // Continue from the glTF camera on screen.
                    s.controller = Controller::from_camera(&opts.scene.cameras[i], &s.bounds);
                }
                s.controller.toggle_projection();
                println!(
                    "camera: {}",
                    if s.controller.orthographic {
                        "orthographic"
                    } else {
                        "perspective"
                    }
                );
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
            KeyAction::Quit => el.exit(),
        }
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, el: &ActiveEventLoop) {
        if self.state.is_some() {
            return;
        }
        match self.init(el) {
            Ok(s) => self.state = Some(s),
            Err(e) => self.fail(el, e),
        }
    }

    fn window_event(&mut self, el: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        if self.state.is_none() {
            return;
        }
        let r: anyhow::Result<()> = match event {
            WindowEvent::CloseRequested => {
                el.exit();
                Ok(())
            }
            WindowEvent::Resized(size) => {
                let s = self.state.as_mut().expect("state");
                s.minimized = size.width == 0 || size.height == 0;
                s.renderer
                    .resize(size.width, size.height)
                    .map_err(Into::into)
            }
            WindowEvent::RedrawRequested => self.redraw(el),
            WindowEvent::KeyboardInput { event, .. } => {
                if let PhysicalKey::Code(code) = event.physical_key {
                    if !event.repeat
                        || matches!(
                            code,
                            KeyCode::ArrowLeft
                                | KeyCode::ArrowRight
                                | KeyCode::ArrowUp
                                | KeyCode::ArrowDown
                        )
                    {
                        self.key(el, code, event.state == ElementState::Pressed);
                    }
                }
                Ok(())
            }
            WindowEvent::MouseInput { state, button, .. } => {
                let b = match button {
                    MouseButton::Left => Some(Button::Left),
                    MouseButton::Right => Some(Button::Right),
                    MouseButton::Middle => Some(Button::Middle),
                    _ => None,
                };
                // A left click that does not move the cursor (3 px) picks.
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
                Ok(())
            }
            WindowEvent::CursorMoved { position, .. } => {
                if let Some(s) = self.state.as_mut() {
                    s.cursor = (position.x as f32, position.y as f32);
                    s.controller
                        .handle(Input::Cursor(position.x as f32, position.y as f32));
                }
                Ok(())
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                self.wheel(lines);
                Ok(())
            }
            _ => Ok(()),
        };
        if let Err(e) = r {
            self.fail(el, e);
        }
    }

    fn about_to_wait(&mut self, el: &ActiveEventLoop) {
        if let Some(s) = &self.state {
            let scripted = s.script_pos < self.opts.script.len();
            if s.minimized && !scripted {
                el.set_control_flow(ControlFlow::Wait);
            } else {
                el.set_control_flow(ControlFlow::Poll);
                s.window.request_redraw();
            }
        }
    }
}

/// Saves a screenshot: the `--screenshot` path on the final frame of a `--frames` run, else a
/// numbered file in the working folder.
fn save_screenshot(
    s: &mut State,
    opts: &ViewerOptions,
    img: &image::RgbaImage,
    final_frame: bool,
) -> anyhow::Result<()> {
    let path = if final_frame {
        opts.screenshot
            .clone()
            .unwrap_or_else(|| PathBuf::from("screenshot.png"))
    } else {
        s.screenshot_count += 1;
        PathBuf::from(format!("umbra-screenshot-{}.png", s.screenshot_count))
    };
    img.save(&path)
        .with_context(|| format!("writing {}", path.display()))?;
    println!(
        "screenshot: {} ({}x{})",
        path.display(),
        img.width(),
        img.height()
    );
    Ok(())
}

/// Puts the frame rate, GPU and CPU times, triangles, map size and animation in the window's
/// title (and the log), four times a second.
fn update_title(s: &mut State, opts: &ViewerOptions) {
    if s.last_title.elapsed().as_secs_f64() >= 0.25 && !s.cpu_ms.is_empty() {
        let n = s.cpu_ms.len() as f64;
        let cpu = s.cpu_ms.iter().sum::<f64>() / n;
        let frame = s.frame_ms.iter().sum::<f64>() / n;
        let gpu = match s.renderer.gpu_times() {
            Some((a, b)) => format!("GPU {:.1} ms (shadow {a:.1} + camera {b:.1})", a + b),
            None => "GPU n/a".into(),
        };
        let anim = if s.player.has_animations() {
            format!(" | {}", s.player.label().trim_start_matches("animation: "))
        } else {
            String::new()
        };
        let title = format!(
            "umbra — {} — {:.1} fps | {gpu} | CPU {cpu:.1} ms | {} tris | map {}²{anim}",
            opts.scene.name,
            1000.0 / frame.max(1e-3),
            s.renderer.triangles(),
            s.view.shadow.map_size
        );
        s.window.set_title(&title);
        log::info!("{title}");
        s.cpu_ms.clear();
        s.frame_ms.clear();
        s.last_title = Instant::now();
    }
}

/// Opens the window and runs until closed (or `frames` are drawn).
pub fn run(opts: ViewerOptions) -> anyhow::Result<()> {
    let event_loop = EventLoop::new().map_err(|e| {
        anyhow!(
            "cannot open a window ({e}); is DISPLAY or WAYLAND_DISPLAY set? Under CI use xvfb-run"
        )
    })?;
    event_loop.set_control_flow(ControlFlow::Poll);
    let mut app = App {
        opts,
        state: None,
        error: None,
    };
    event_loop
        .run_app(&mut app)
        .map_err(|e| anyhow!("window event loop failed: {e}"))?;
    if let Some(e) = app.error.take() {
        return Err(e);
    }
    #[allow(unused_mut)] // mutated only with the `sweep` feature
    if let Some(mut s) = app.state.take() {
        if let (Some(t), true) = (s.first_draw, s.drawn > 1) {
            let secs = t.elapsed().as_secs_f64();
            println!(
                "viewer: {} frames in {secs:.2} s ({:.1} fps, vsync {})",
                s.drawn,
                (s.drawn - 1) as f64 / secs,
                if app.opts.vsync { "on" } else { "off" }
            );
        }
        if let (Some(warm), Some(end)) = (s.rss_warm, resident_bytes()) {
            println!(
                "viewer: resident memory {:.1} MB after {WARM_UP_FRAMES} frames, {:.1} MB after {} (growth {:.2} MB)",
                warm as f64 / 1e6,
                end as f64 / 1e6,
                s.drawn,
                (end as f64 - warm as f64) / 1e6
            );
        }
        // Keep the log past the teardown, so messages from destroying objects count too.
        let log = s.ctx.validation_log.clone();
        #[cfg(feature = "sweep")]
        let worker_problems = match s.budget.take() {
            Some(b) => b.finish()?,
            None => 0,
        };
        #[cfg(not(feature = "sweep"))]
        let worker_problems = 0;
        drop(s);
        let problems = log.problem_count() + worker_problems;
        if problems > 0 {
            anyhow::bail!("{problems} validation message(s) of warning or error severity");
        }
    }
    Ok(())
}
