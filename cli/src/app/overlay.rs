//! The viewer's egui glue: input from winit (`egui-winit`), one UI pass per frame, and drawing
//! the tessellated panel into the window's frame with `egui-ash-renderer` on the engine's own
//! Vulkan device (through `umbra::render::Overlay`, recorded after the scene).

use ash::vk;
use egui_ash_renderer::{DynamicRendering, Options, RenderMode, Renderer};
use std::sync::Arc;
use umbra::gpu::Context;
use winit::window::Window;

/// egui's context, input state and renderer, and the last pass's triangles.
pub struct EguiOverlay {
    /// The egui context (its memory keeps the panel's state between frames).
    pub ctx: egui::Context,
    input: egui_winit::State,
    // Dropped before the pool and the device (a field's drop order is its place here).
    renderer: Renderer<egui_ash_renderer::allocator::DefaultAllocator>,
    primitives: Vec<egui::ClippedPrimitive>,
    pixels_per_point: f32,
    /// Textures egui released, freed once no frame in flight can read them.
    to_free: Vec<egui::TextureId>,
    pool: vk::CommandPool,
    gpu: Arc<Context>,
}

/// Whether a window event went to the panel (the viewer then leaves it alone).
#[derive(Clone, Copy, Debug, Default)]
pub struct Consumed {
    /// The panel took a pointer event (a click or drag over it).
    pub pointer: bool,
    /// The panel took a key (a text field has focus).
    pub keyboard: bool,
}

impl EguiOverlay {
    /// An overlay for `window`, drawing into swapchain images of `format` on `gpu`'s device.
    pub fn new(gpu: &Arc<Context>, window: &Window, format: vk::Format) -> anyhow::Result<Self> {
        let raw = gpu.raw();
        let pool = unsafe {
            raw.device.create_command_pool(
                &vk::CommandPoolCreateInfo::default()
                    .queue_family_index(raw.queue_family)
                    .flags(vk::CommandPoolCreateFlags::TRANSIENT),
                None,
            )
        }?;
        let srgb = matches!(
            format,
            vk::Format::B8G8R8A8_SRGB | vk::Format::R8G8B8A8_SRGB
        );
        let renderer = Renderer::with_default_allocator(
            raw.instance,
            raw.physical,
            raw.device.clone(),
            RenderMode::DynamicRendering(DynamicRendering {
                color_attachment_format: format,
                depth_attachment_format: None,
                stencil_attachment_format: None,
            }),
            Options {
                in_flight_frames: umbra::render::FRAMES_IN_FLIGHT,
                srgb_framebuffer: srgb,
                ..Default::default()
            },
        )
        .map_err(|e| {
            unsafe { raw.device.destroy_command_pool(pool, None) };
            anyhow::anyhow!("cannot create the panel's renderer: {e}")
        })?;
        let ctx = egui::Context::default();
        let input = egui_winit::State::new(
            ctx.clone(),
            egui::ViewportId::ROOT,
            window,
            Some(window.scale_factor() as f32),
            None,
            None,
        );
        Ok(Self {
            ctx,
            input,
            renderer,
            primitives: Vec::new(),
            pixels_per_point: 1.0,
            to_free: Vec::new(),
            pool,
            gpu: gpu.clone(),
        })
    }

    /// Hands a window event to egui; says what it took.
    pub fn on_window_event(
        &mut self,
        window: &Window,
        event: &winit::event::WindowEvent,
    ) -> Consumed {
        use winit::event::WindowEvent as E;
        let r = self.input.on_window_event(window, event);
        let pointer = matches!(
            event,
            E::MouseInput { .. } | E::MouseWheel { .. } | E::CursorMoved { .. }
        ) && (r.consumed || self.ctx.egui_wants_pointer_input());
        let keyboard = matches!(event, E::KeyboardInput { .. })
            && (r.consumed && self.ctx.egui_wants_keyboard_input());
        Consumed { pointer, keyboard }
    }

    /// Runs one UI pass with `ui`, `extra` input events appended (scripted clicks), uploads the
    /// textures it changed and keeps its triangles for `record`. Waits for the device first
    /// when textures change (rare: the font atlas growing), since a frame in flight may read
    /// them.
    pub fn run(
        &mut self,
        window: &Window,
        extra: Vec<egui::Event>,
        ui: impl FnMut(&mut egui::Ui),
    ) -> anyhow::Result<()> {
        let mut input = self.input.take_egui_input(window);
        input.events.extend(extra);
        let mut out = self.ctx.run_ui(input, ui);
        self.input
            .handle_platform_output(window, out.platform_output);
        let raw = self.gpu.raw();
        if !out.textures_delta.set.is_empty() || !self.to_free.is_empty() {
            unsafe { raw.device.device_wait_idle() }?;
            for id in self.to_free.drain(..) {
                self.renderer.free_texture(id)?;
            }
            for (id, deltas) in out.textures_delta.set.drain() {
                for delta in deltas {
                    self.renderer
                        .set_texture(raw.queue, self.pool, id, &delta)?;
                }
            }
        }
        self.to_free
            .extend(std::mem::take(&mut out.textures_delta.free));
        self.pixels_per_point = out.pixels_per_point;
        self.primitives = self.ctx.tessellate(out.shapes, out.pixels_per_point);
        Ok(())
    }

    /// Forgets the last pass's triangles (the panel is hidden).
    pub fn clear(&mut self) {
        self.primitives.clear();
    }
}

impl umbra::render::Overlay for EguiOverlay {
    fn record(&mut self, cmd: vk::CommandBuffer, extent: vk::Extent2D) {
        if let Err(e) = self
            .renderer
            .cmd_draw(cmd, extent, self.pixels_per_point, &self.primitives)
        {
            log::warn!("panel not drawn: {e}");
        }
    }
}

impl Drop for EguiOverlay {
    fn drop(&mut self) {
        let raw = self.gpu.raw();
        unsafe {
            let _ = raw.device.device_wait_idle();
            raw.device.destroy_command_pool(self.pool, None);
        }
    }
}
