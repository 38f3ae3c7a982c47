//! Opening the viewer: the window, the validated context, the window renderer, the panel and
//! the state the first frame starts from.

use super::*;
use crate::app::actions::SunAngles;
use crate::app::controller::Controller;
use crate::app::overlay::EguiOverlay;
use crate::app::panel::{Stats, Widgets};
use anyhow::{anyhow, Context as _};
use std::sync::Arc;
use std::time::Instant;
use umbra::gpu::{Context, ContextDesc, Validation};
use umbra::plan::effective_lights;
use umbra::render::{surface_extensions, WindowRenderer};
use umbra::scene::LightKind;
use winit::dpi::PhysicalSize;
use winit::event_loop::ActiveEventLoop;
use winit::raw_window_handle::{HasDisplayHandle, HasWindowHandle};
use winit::window::Window;

impl App {
    pub(super) fn init(&mut self, el: &ActiveEventLoop) -> anyhow::Result<State> {
        #[cfg(not(feature = "sweep"))]
        if self.opts.shadow_budget.is_some() {
            anyhow::bail!("--shadow-budget needs umbra built with the `sweep` feature");
        }
        let (window, ctx, renderer) = self.open_window(el)?;
        let size = window.inner_size();
        let overlay = EguiOverlay::new(&ctx, &window, renderer.format())
            .map_err(|e| eprintln!("warning: no panel: {e:#}"))
            .ok();
        let view = self.opts.view.clone();
        let bounds = framing_bounds(&self.opts.scene);
        let controller = Controller::from_camera(&view.camera, &bounds);
        let sun = self.first_sun(&view);
        println!(
            "viewer: {} on {} ({} triangles); press Esc to quit, F1 for the panel",
            self.opts.scene.name,
            ctx.device_name,
            renderer.triangles()
        );
        let (watch, tree) = self.watch_and_tree();
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
            sun,
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
            panel: self.first_panel(triangles, tree),
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

    /// The sun the panel starts from: the first directional light of `view` (straight down
    /// without one).
    fn first_sun(&self, view: &umbra::plan::View) -> SunAngles {
        let lights = effective_lights(&self.opts.scene.lights, view);
        let sun_dir = lights
            .iter()
            .find(|l| l.kind == LightKind::Directional)
            .map(|l| l.direction)
            .unwrap_or(glam::Vec3::NEG_Y);
        SunAngles::from_direction(sun_dir)
    }

    /// The model file watched for changes (a warning where it cannot be), and its files' tree
    /// for the panel.
    fn watch_and_tree(
        &self,
    ) -> (
        Option<crate::app::reload::Watch>,
        Option<crate::app::scene_tree::SceneTree>,
    ) {
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
        (watch, tree)
    }

    /// The window, a context that can present to it, and the window renderer of the scene.
    fn open_window(
        &self,
        el: &ActiveEventLoop,
    ) -> anyhow::Result<(Arc<Window>, Arc<Context>, WindowRenderer)> {
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
        Ok((window, ctx, renderer))
    }

    /// The panel as the first frame shows it.
    fn first_panel(
        &self,
        triangles: usize,
        tree: Option<crate::app::scene_tree::SceneTree>,
    ) -> PanelState {
        PanelState {
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
        }
    }
}
