//! `umbra view`: the real-time viewer (winit). Same passes as the offscreen path; orbit/fly
//! cameras, perspective or orthographic; an on-screen panel (egui, `F1`) with the frame's
//! figures, every setting, the pick result and the scene tree; keys for the same settings, each
//! change printed; a dropped file opens, and the model reloads when it changes on disk; `P`
//! saves a screenshot. Key bindings: `keys`; the panel: `crate::app::panel`.

mod files;
mod keys;
mod ui;

use crate::app::actions::{apply, next_shadow_light, SunAngles};
use crate::app::controller::{Button, Controller, Input};
use crate::app::overlay::EguiOverlay;
use crate::app::panel::{Stats, Widgets};
use crate::app::script::ScriptStep;
use anyhow::{anyhow, Context as _};
use keys::{key_action, script_key, AnimKey, KeyAction};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;
use umbra::gpu::{Context, ContextDesc, Validation};
use umbra::render::{effective_lights, surface_extensions, Capture, DrawResult, WindowRenderer};
use umbra::render::{Overlay, View};
use umbra::scene::{LightKind, Scene};
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::raw_window_handle::{HasDisplayHandle, HasWindowHandle};
use winit::window::{Window, WindowId};

/// Loads a model for the viewer as the command line loaded the first one (ground, pose).
pub type Loader = Box<dyn Fn(&Path) -> anyhow::Result<Scene>>;

/// How to run the viewer.
pub struct ViewerOptions {
    /// The scene.
    pub scene: Scene,
    /// The file it was loaded from (watched, and reloaded when it changes; None for built-in
    /// scenes).
    pub path: Option<PathBuf>,
    /// How to load a dropped or changed file.
    pub loader: Loader,
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
    /// Screenshots hold the panel too (else the scene alone).
    pub screenshot_ui: bool,
    /// The panel is shown at the start (`F1` toggles it).
    pub panel: bool,
    /// Device name substring.
    pub device: Option<String>,
    /// Khronos validation on (exit 1 on any message).
    pub validation: bool,
    /// Inputs to play, one every few frames (automation, tests): `crate::app::script`.
    pub script: Vec<ScriptStep>,
    /// Re-choose the shadow settings for this misclassification budget as the camera moves.
    pub shadow_budget: Option<f64>,
    /// Where the animation clock starts (`--animation`, `--time`: paused there); None: the
    /// first animation plays from 0.
    pub start: Option<(umbra::scene::anim::Playing, f32)>,
}

/// Frames between two script steps.
const SCRIPT_STEP_FRAMES: u64 = 2;
/// Frames after which resident memory is sampled for the end-of-run report.
const WARM_UP_FRAMES: u64 = 100;
/// How long `wait:reload` waits.
const RELOAD_WAIT: std::time::Duration = std::time::Duration::from_secs(30);

/// Resident set size of this process in bytes (Linux; None elsewhere).
fn resident_bytes() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/statm").ok()?;
    let pages: u64 = s.split_whitespace().nth(1)?.parse().ok()?;
    Some(pages * 4096)
}

/// The panel's state in the viewer.
struct PanelState {
    /// Shown.
    open: bool,
    /// The last pass's widgets, for scripted clicks.
    widgets: Widgets,
    /// Input events for the next pass (scripted clicks); the release of a scripted press, and
    /// that release once due (on the pass after the press's).
    events: Vec<egui::Event>,
    release: Option<egui::Pos2>,
    release_due: Option<egui::Pos2>,
    /// Frame figures.
    stats: Stats,
    /// The last pick's report.
    pick: Option<String>,
    /// The glTF scene tree, and the node selected in it.
    tree: Option<crate::app::scene_tree::SceneTree>,
    selected: Option<usize>,
    /// The last load's message.
    status: Option<String>,
}

struct State {
    // Field order is drop order: GPU objects (the panel's, the renderers) before the context, the
    // renderer (swapchain, surface) before the window.
    overlay: Option<EguiOverlay>,
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
    player: crate::app::player::Player,
    pose_dirty: bool,
    panel: PanelState,
    /// The model's folder, watched for changes.
    watch: Option<crate::app::reload::Watch>,
    /// Reloads done, and since when a `wait:reload` step waits (with the count it waits past).
    reloads: u64,
    waiting: Option<(Instant, u64)>,
    #[cfg(feature = "sweep")]
    budget: Option<crate::app::budget_worker::BudgetWorker>,
    /// The budget in force, and the validation messages of budget workers already finished.
    budget_value: Option<f64>,
    worker_problems: usize,
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
            validation: Validation::required_if(self.opts.validation),
            device: self.opts.device.clone(),
            instance_extensions,
            swapchain: true,
            pipeline_cache: crate::app::pipeline_cache_path(),
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
        let overlay = EguiOverlay::new(&ctx, &window, renderer.format())
            .map_err(|e| eprintln!("warning: no panel: {e:#}"))
            .ok();
        let view = self.opts.view.clone();
        let bounds = framing_bounds(&self.opts.scene);
        let controller = Controller::from_camera(&view.camera, &bounds);
        let lights = effective_lights(&self.opts.scene.lights, &view);
        let sun_dir = lights
            .iter()
            .find(|l| l.kind == LightKind::Directional)
            .map(|l| l.direction)
            .unwrap_or(glam::Vec3::NEG_Y);
        println!(
            "viewer: {} on {} ({} triangles); press Esc to quit, F1 for the panel",
            self.opts.scene.name,
            ctx.device_name,
            renderer.triangles()
        );
        let watch = self.opts.path.as_deref().and_then(|p| {
            crate::app::reload::Watch::new(p)
                .map_err(|e| eprintln!("warning: {}: not watched for changes: {e}", p.display()))
                .ok()
        });
        let tree = self
            .opts
            .path
            .as_deref()
            .and_then(|p| files::tree_of(p, &self.opts.scene));
        let triangles = renderer.triangles();
        Ok(State {
            overlay,
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
            player: crate::app::player::Player::new(
                self.opts.scene.rig.as_deref(),
                self.opts.start.clone(),
            ),
            pose_dirty: false,
            panel: PanelState {
                open: self.opts.panel,
                widgets: Widgets::default(),
                events: Vec::new(),
                release: None,
                release_due: None,
                stats: Stats {
                    triangles,
                    ..Default::default()
                },
                pick: None,
                tree,
                selected: None,
                status: None,
            },
            watch,
            reloads: 0,
            waiting: None,
            #[cfg(feature = "sweep")]
            budget: self.opts.shadow_budget.map(|b| {
                crate::app::budget_worker::BudgetWorker::start(
                    self.opts.scene.clone(),
                    b,
                    self.opts.device.clone(),
                    self.opts.validation,
                )
            }),
            budget_value: self.opts.shadow_budget,
            worker_problems: 0,
        })
    }

    /// Runs the input script's next step when it is due (one every `SCRIPT_STEP_FRAMES` frames;
    /// none while a `wait:reload` waits).
    fn script_step(&mut self, el: &ActiveEventLoop) -> anyhow::Result<()> {
        let step = {
            let Some(s) = self.state.as_mut() else {
                return Ok(());
            };
            s.ticks += 1;
            if let Some((since, count)) = s.waiting {
                if s.reloads > count {
                    s.waiting = None;
                } else if since.elapsed() > RELOAD_WAIT {
                    anyhow::bail!("script: wait:reload: no reload within {RELOAD_WAIT:?}");
                } else {
                    return Ok(());
                }
            }
            let due = s.ticks % SCRIPT_STEP_FRAMES == 0 && s.script_pos < self.opts.script.len();
            due.then(|| {
                s.script_pos += 1;
                self.opts.script[s.script_pos - 1].clone()
            })
        };
        let Some(step) = step else {
            return Ok(());
        };
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
            ScriptStep::Ui(name) => self.click_widget(&name)?,
            ScriptStep::Drop(path) => self.open(&path, true),
            ScriptStep::Copy(from, to) => {
                std::fs::copy(&from, &to).with_context(|| {
                    format!("script: copy {} to {}", from.display(), to.display())
                })?;
            }
            ScriptStep::WaitReload => s.waiting = Some((Instant::now(), s.reloads)),
        }
        Ok(())
    }

    fn redraw(&mut self, el: &ActiveEventLoop) -> anyhow::Result<()> {
        self.script_step(el)?;
        self.reload_if_changed();
        let Some(s) = self.state.as_mut() else {
            return Ok(());
        };
        let now = Instant::now();
        let dt = (now - s.last_frame).as_secs_f32().min(0.25);
        s.last_frame = now;
        // The animation: wall time, or one frame step per frame in a run of --frames (so what
        // it draws does not depend on the machine's speed). Posing counts as CPU time.
        let clock = if self.opts.frames.is_some() {
            crate::app::player::FRAME_STEP
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
        s.controller.update(dt);
        if s.camera_index.is_none() {
            s.view.camera = s.controller.camera();
        }
        self.poll_budget()?;
        let t0 = Instant::now();
        self.run_panel(el)?;
        let opts = &self.opts;
        let s = self.state.as_mut().expect("state");
        let last_scripted = s.script_pos >= opts.script.len() && s.waiting.is_none();
        let final_frame = opts.frames.is_some_and(|n| s.drawn + 1 >= n) && last_scripted;
        let shot = s.want_screenshot || (final_frame && opts.screenshot.is_some());
        let capture = match (shot, opts.screenshot_ui) {
            (false, _) => Capture::None,
            (true, false) => Capture::Scene,
            (true, true) => Capture::Screen,
        };
        let overlay = match (&mut s.overlay, s.panel.open) {
            (Some(o), true) => Some(o as &mut dyn Overlay),
            _ => None,
        };
        let result = if s.minimized {
            DrawResult::Skipped
        } else {
            s.renderer.draw_with(&s.view, capture, overlay)?
        };
        let cpu = t0.elapsed().as_secs_f64() * 1e3 + pose_ms;
        if let DrawResult::Drawn {
            screenshot,
            summary,
        } = result
        {
            s.drawn += 1;
            if s.drawn == WARM_UP_FRAMES {
                s.rss_warm = resident_bytes();
            }
            s.first_draw.get_or_insert(t0);
            s.cpu_ms.push(cpu);
            s.frame_ms.push(dt as f64 * 1e3);
            s.panel.stats.summary = summary;
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

    /// Asks the budget worker for settings for the current view and applies its answer.
    fn poll_budget(&mut self) -> anyhow::Result<()> {
        #[cfg(feature = "sweep")]
        {
            let wait = self.opts.frames.is_some();
            let Some(s) = self.state.as_mut() else {
                return Ok(());
            };
            if let Some(b) = s.budget.as_mut() {
                let size = s.window.inner_size();
                b.request(&s.view, (size.width, size.height));
                // A run of a fixed number of frames (automation) waits for each choice, so
                // what it draws and prints does not depend on the machine's speed.
                if let Some(out) = b.poll(&mut s.view, wait)? {
                    let label =
                        umbra_lab::analysis::chart::short_label_of(&out.choice.chosen.config);
                    let line = crate::app::cli::budget_line(&out.choice, &label);
                    if out.kept {
                        println!("{line}; keeping the running settings (within budget here)");
                    } else {
                        println!("{line}");
                    }
                }
            }
        }
        Ok(())
    }

    /// Picks at window position (`x`, `y`): reports what is there (printed and in the panel)
    /// and highlights its primitive (nothing there: clears the highlight).
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
    fn pick(&mut self, x: f32, y: f32) {
        let line = format!(
            "pick: ({x:.0}, {y:.0}): picking needs umbra built with the `reference` feature"
        );
        println!("{line}");
        if let Some(s) = self.state.as_mut() {
            s.panel.pick = Some(line);
        }
    }

    fn wheel(&mut self, lines: f32) {
        if let Some(s) = self.state.as_mut() {
            s.camera_index = None;
            s.controller.handle(Input::Scroll(lines));
        }
    }

    fn key(&mut self, el: &ActiveEventLoop, code: KeyCode, pressed: bool) {
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
    fn act(&mut self, el: &ActiveEventLoop, action: KeyAction) {
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
    fn use_camera(&mut self, i: Option<usize>) {
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
    fn mouse(&mut self, state: ElementState, button: MouseButton) {
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

/// What the camera frames and scales its speeds by (the model, not a helper ground).
fn framing_bounds(scene: &Scene) -> umbra::math::Aabb {
    scene.framing.unwrap_or_else(|| scene.bounds())
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
        let Some(s) = self.state.as_mut() else {
            return;
        };
        // The panel sees every event first; what it takes goes no further.
        let taken = match (&mut s.overlay, s.panel.open) {
            (Some(o), true) => o.on_window_event(&s.window, &event),
            _ => Default::default(),
        };
        let r: anyhow::Result<()> = match event {
            WindowEvent::CloseRequested => {
                el.exit();
                Ok(())
            }
            WindowEvent::Resized(size) => {
                s.minimized = size.width == 0 || size.height == 0;
                s.renderer
                    .resize(size.width, size.height)
                    .map_err(Into::into)
            }
            WindowEvent::RedrawRequested => self.redraw(el),
            WindowEvent::DroppedFile(path) => {
                self.open(&path, true);
                Ok(())
            }
            WindowEvent::KeyboardInput { event, .. } if !taken.keyboard => {
                if let PhysicalKey::Code(code) = event.physical_key {
                    let arrow = matches!(
                        code,
                        KeyCode::ArrowLeft
                            | KeyCode::ArrowRight
                            | KeyCode::ArrowUp
                            | KeyCode::ArrowDown
                    );
                    if !event.repeat || arrow {
                        self.key(el, code, event.state == ElementState::Pressed);
                    }
                }
                Ok(())
            }
            WindowEvent::MouseInput { state, button, .. } => {
                // A press over the panel is the panel's; a release always reaches the camera
                // (a drag that started on the scene ends wherever it ends).
                if !taken.pointer || state == ElementState::Released {
                    self.mouse(state, button);
                }
                Ok(())
            }
            WindowEvent::CursorMoved { position, .. } => {
                s.cursor = (position.x as f32, position.y as f32);
                s.controller
                    .handle(Input::Cursor(position.x as f32, position.y as f32));
                Ok(())
            }
            WindowEvent::MouseWheel { delta, .. } if !taken.pointer => {
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
            let scripted = s.script_pos < self.opts.script.len() || s.waiting.is_some();
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
/// title (and the log) and the panel's figures, four times a second.
fn update_title(s: &mut State, opts: &ViewerOptions) {
    if s.last_title.elapsed().as_secs_f64() >= 0.25 && !s.cpu_ms.is_empty() {
        let n = s.cpu_ms.len() as f64;
        let cpu = s.cpu_ms.iter().sum::<f64>() / n;
        let frame = s.frame_ms.iter().sum::<f64>() / n;
        let gpu_times = s.renderer.gpu_times();
        let gpu = match gpu_times {
            Some((a, b)) => format!("GPU {:.1} ms (shadow {a:.1} + camera {b:.1})", a + b),
            None => "GPU n/a".into(),
        };
        let anim = if s.player.has_animations() {
            format!(" | {}", s.player.label().trim_start_matches("animation: "))
        } else {
            String::new()
        };
        let fps = 1000.0 / frame.max(1e-3);
        let title = format!(
            "umbra — {} — {fps:.1} fps | {gpu} | CPU {cpu:.1} ms | {} tris | map {}²{anim}",
            opts.scene.name,
            s.renderer.triangles(),
            s.view.shadow.map_size
        );
        s.window.set_title(&title);
        log::info!("{title}");
        let st = &mut s.panel.stats;
        (st.fps, st.cpu_ms, st.gpu_ms) = (fps, cpu, gpu_times);
        st.triangles = s.renderer.triangles();
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
        if let Some(b) = s.budget.take() {
            s.worker_problems += b.finish()?;
        }
        let worker_problems = s.worker_problems;
        drop(s);
        let problems = log.problem_count() + worker_problems;
        if problems > 0 {
            anyhow::bail!("{problems} validation message(s) of warning or error severity");
        }
    }
    Ok(())
}
