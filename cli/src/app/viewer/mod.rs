//! `umbra view`: the real-time viewer (winit). Same passes as the offscreen path; orbit/fly
//! cameras, perspective or orthographic; an on-screen panel (egui, `F1`) with the frame's
//! figures, every setting, the pick result and the scene tree; keys for the same settings, each
//! change printed; a dropped file opens, and the model reloads when it changes on disk; `P`
//! saves a screenshot. Key bindings: `keys`; the panel: `crate::app::panel`.

mod files;
mod init;
mod input;
mod keys;
mod ui;

use crate::app::actions::SunAngles;
use crate::app::controller::{Controller, Input};
use crate::app::overlay::EguiOverlay;
use crate::app::panel::{Stats, Widgets};
use crate::app::script::ScriptStep;
use anyhow::{anyhow, Context as _};
use keys::script_key;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;
use umbra::gpu::Context;
use umbra::plan::View;
use umbra::render::Overlay;
use umbra::render::{Capture, DrawResult, WindowRenderer};
use umbra::scene::Scene;
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{KeyCode, PhysicalKey};
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
    pub scene_options: umbra::plan::SceneOptions,
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
