//! What a frame is rendered with: view, shadow and output settings.

pub use crate::math::tonemap::Tonemap;

/// Linear colour where nothing is drawn (the CPU reference uses it too).
pub const CLEAR_COLOR: [f32; 4] = [0.02, 0.02, 0.025, 1.0];

/// What the camera pass writes (the command line's `--view`; `clap::ValueEnum` with the `clap` feature).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum ViewMode {
    /// The shaded image.
    #[default]
    Lit,
    /// The shadowed light's visibility term alone (the factor the lit image multiplies by):
    /// 255 where lit, 0 where blocked or facing away, grey in filtered penumbrae.
    Shadow,
    /// World normals after normal mapping, encoded n·0.5+0.5.
    Normals,
    /// The shadow map itself (grey = depth, reversed-z: white is near the light).
    ShadowMap,
    /// Which shadow view (cascade) shades each pixel: red, green, blue, yellow for cascades 0–3,
    /// darkened where in shadow; grey where no map is read.
    Cascades,
    /// Texture coordinates 0 as a grey checker, 8 cells per unit (bytes 38 and 217).
    UvChecker,
    /// World tangents after orthogonalising against the normal, encoded t·0.5+0.5.
    Tangents,
    /// World bitangents (n × t · w), encoded b·0.5+0.5.
    Bitangents,
    /// Base colour (factor × texture), as stored: sRGB bytes, no lighting.
    BaseColor,
    /// Metallic (factor × texture blue) as grey bytes.
    Metallic,
    /// Roughness (factor × texture green) as grey bytes.
    Roughness,
    /// Linear view depth: white at the eye, black at the scene's far end (`1 − z / z_far`).
    Depth,
    /// Screen pixels per shadow-map texel as a heat map, log2 over 1/16…16: dark blue where
    /// texels are finer than pixels, teal-yellow near 1:1, white where a texel spans many pixels
    /// (blocky shadows). Grey without a shadow map.
    TexelDensity,
    /// Fragments rasterised per pixel (no depth test, additive): each adds 1/16 in linear light,
    /// so a pixel's byte decodes to n/16 (n up to 16).
    Overdraw,
}

impl ViewMode {
    /// Shader constant.
    pub fn shader_value(self) -> u32 {
        use crate::shader_consts::scene as sh;
        match self {
            ViewMode::Lit | ViewMode::ShadowMap => sh::VIEW_LIT,
            ViewMode::Shadow => sh::VIEW_SHADOW,
            ViewMode::Normals => sh::VIEW_NORMALS,
            ViewMode::Cascades => sh::VIEW_CASCADES,
            ViewMode::UvChecker => sh::VIEW_UV_CHECKER,
            ViewMode::Tangents => sh::VIEW_TANGENTS,
            ViewMode::Bitangents => sh::VIEW_BITANGENTS,
            ViewMode::BaseColor => sh::VIEW_BASE_COLOR,
            ViewMode::Metallic => sh::VIEW_METALLIC,
            ViewMode::Roughness => sh::VIEW_ROUGHNESS,
            ViewMode::Depth => sh::VIEW_DEPTH,
            ViewMode::TexelDensity => sh::VIEW_TEXEL_DENSITY,
            ViewMode::Overdraw => sh::VIEW_OVERDRAW,
        }
    }
}

/// Shadow-map filtering kernel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pcf {
    /// One nearest-texel comparison.
    None,
    /// One bilinear 2×2 comparison.
    P2x2,
    /// 3×3 bilinear taps at one-texel spacing (a 4×4-texel footprint).
    P3x3,
    /// 5×5 bilinear taps (a 6×6-texel footprint).
    P5x5,
}

impl Pcf {
    /// Bilinear taps per side (0 for nearest).
    pub fn taps(self) -> u32 {
        match self {
            Pcf::None => 0,
            Pcf::P2x2 => 1,
            Pcf::P3x3 => 3,
            Pcf::P5x5 => 5,
        }
    }

    /// How many texels from its centre a lookup reads: half the kernel's bilinear taps, plus the
    /// 2×2 texels of each tap (1 for the single nearest comparison).
    pub fn lookup_reach(self) -> u32 {
        self.taps().saturating_sub(1) / 2 + 1
    }
}

/// Depth format of the shadow map.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShadowFormat {
    /// 32-bit float.
    D32,
    /// 16-bit unorm.
    D16,
    /// Per frame (the default): D16 where its depth step is too small to matter (every view
    /// orthographic and its step at most a quarter of the constant bias, `plan::resolve_format`),
    /// else D32. Half the bytes a texel to write and read.
    Auto,
}

impl std::str::FromStr for ShadowFormat {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "d32" => Ok(Self::D32),
            "d16" => Ok(Self::D16),
            "auto" => Ok(Self::Auto),
            _ => Err(format!("shadow format '{s}' is not auto, d16 or d32")),
        }
    }
}

/// How the shadowed light's visibility is decided.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ShadowMethod {
    /// Shadow maps (the default): cascades, PCF or PCSS, bias.
    #[default]
    Map,
    /// Exact hard shadows by an irregular z-buffer (`crate::render::passes::exact`): each pixel's
    /// shadow ray tested against the caster triangles themselves, no bias, no texels. For one
    /// shadowed light: directional (the map's single cascade behind it), spot, or point (a grid
    /// per cube face); frames with several shadowed lights, and devices without fragment-shader
    /// stores, use maps. Hard: a light's size is ignored.
    Exact,
    /// Exact shadows where the map cannot prove its answer (`docs/exact-shadows.md`, *Hybrid*):
    /// a pixel whose nine nearest map texels all agree, by a margin, with the light depth of
    /// its own surface keeps the map's verdict; the others are traced as [`ShadowMethod::Exact`]
    /// traces them, against only the casters that reach their cells. Directional and spot
    /// lights; a point light's cube is traced whole.
    Hybrid,
}

impl ShadowMethod {
    /// Whether shadow rays decide some pixels (exact or hybrid).
    pub fn traces(self) -> bool {
        self != Self::Map
    }
}

impl std::str::FromStr for ShadowMethod {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "map" => Ok(Self::Map),
            "exact" => Ok(Self::Exact),
            "hybrid" => Ok(Self::Hybrid),
            _ => Err(format!("shadow method '{s}' is not map, exact or hybrid")),
        }
    }
}

/// Anti-aliasing applied to the finished lit image (after any MSAA resolve).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum PostAa {
    /// None (the default: pictures as drawn).
    #[default]
    None,
    /// FXAA (Lottes 2009, the published "quality" algorithm): each pixel whose 3×3 luma range
    /// marks an edge is resampled across the edge by its estimated coverage; flat pixels are
    /// copied unchanged. One full-screen pass: the smooth-edge option a CPU device can afford
    /// (docs/speed.md has its cost and edge error beside MSAA's).
    Fxaa,
}

impl std::str::FromStr for PostAa {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "none" | "off" => Ok(Self::None),
            "fxaa" => Ok(Self::Fxaa),
            _ => Err(format!("post anti-aliasing '{s}' is not none or fxaa")),
        }
    }
}

/// How the directional light's frustum is fitted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShadowFit {
    /// To the camera frustum ∩ scene bounds (receivers), extended to all casters.
    Camera,
    /// To the whole scene bounds.
    Scene,
    /// To the camera like `Camera`, but each map (or cascade) covers the bounding sphere of its
    /// slice of the camera frustum, within the scene's bounds: its size does not change as the
    /// camera moves or turns (only with the depth range, field of view and aspect), so snapped
    /// maps step, and shimmer, far less often, for coarser texels than `Camera` (1.2–2× on the
    /// built-in and sample scenes' first views).
    Sphere,
}

/// Shadow settings. Biases are in the units named; the defaults were chosen by the acne and
/// peter-panning tests (`tests/gpu_shadows.rs`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowSettings {
    /// Shadows on or off.
    pub enabled: bool,
    /// Shadow maps or exact shadows.
    pub method: ShadowMethod,
    /// Contact shadows over the maps (`crate::render::passes::exact`): each pixel's shadow ray
    /// marched a few texels towards the shown light through the depth the camera sees, dark where
    /// it passes behind a surface. Restores contact detail finer than the map's texels; sees only
    /// what the camera sees. Hard shadows only (not with PCSS), devices with fragment-shader
    /// stores; ignored with exact shadows, which need none.
    pub contact: bool,
    /// Map size in texels (square), within [`ShadowSettings::MAP_SIZES`] (the renderer clamps
    /// other values into it).
    pub map_size: u32,
    /// Depth format.
    pub format: ShadowFormat,
    /// Filter.
    pub pcf: Pcf,
    /// Constant bias in shadow texels: the receiver's lookup point moves this many texel widths
    /// towards the light (so the bias follows the texel's world size).
    pub constant_bias: f32,
    /// Slope-scaled depth bias (hardware, multiplies the caster's depth slope), applied away from
    /// the light (negated internally for reversed-z).
    pub slope_bias: f32,
    /// Normal-offset bias in shadow texels (scaled by the texel's world size and sin θ).
    pub normal_offset: f32,
    /// Frustum fitting.
    pub fit: ShadowFit,
    /// Snap the fitted frustum to whole texels (stable under camera motion).
    pub snap: bool,
    /// With `snap`, steps per doubling of the fitted extent's ladder: the map changes size only
    /// when the extent crosses a step, and each change moves every shadow edge by up to a texel
    /// (shimmer). 8 (the default, 2^(1/8) apart) costs 4.5 % in texel size on average; 1 (powers
    /// of two) steps 7× less often on the stability suite's FlightHelmet flythrough (shimmer
    /// 3.1·10⁻⁴ → 8.7·10⁻⁵ per frame) for 44 % coarser texels on average (17 % along that path).
    pub extent_steps: u32,
    /// Cascades of a directional light's map fitted to the camera (1–4; `MAX_CASCADES`): each
    /// covers a slice of the view depth with its own `map_size`² layer. 1 is the single map; 0
    /// (the default) chooses per frame from how much coarser than a pixel one map's texels would
    /// be at the nearest receiver (`plan::views::auto_cascades`), drawing one map of twice the
    /// side instead of two cascades where that suffices (`plan::views::auto_doubles_map`).
    pub cascades: u32,
    /// Side in texels of each of a point light's six cube faces (each fills that square of its
    /// own layer); 0 (the default) is half of `map_size`, so a cube costs 1.5 maps of texels, not
    /// six.
    pub cube_face: u32,
    /// Sample-distribution fitting (SDSM, Lauritzen et al. 2010): a directional light's cascades
    /// are split over, and fitted to, the view depths the camera actually sees (the nearest and
    /// farthest depth in its depth buffer, grown by 1 %) instead of where its frustum meets the
    /// receivers' boxes, so a view that sees only near things spends every texel near. The
    /// offscreen renderer measures them with a first pass at each new camera (a frame at a new
    /// camera costs two); `View::visible_depths` can also be given.
    pub depth_fit: bool,
    /// Soft shadows (PCSS) for lights with a size (`crate::scene::Light::size`); false: hard
    /// PCF whatever their size (the sweep's hard configurations against an area light).
    pub soft: bool,
}

/// Most cascades a directional light can have.
pub const MAX_CASCADES: u32 = 4;

impl ShadowSettings {
    /// The shadow-map sizes the renderer accepts, in texels: the one range every front end
    /// checks against.
    pub const MAP_SIZES: std::ops::RangeInclusive<u32> = 16..=16384;

    /// `map_size` clamped into [`Self::MAP_SIZES`].
    pub fn clamped_map_size(&self) -> u32 {
        self.map_size
            .clamp(*Self::MAP_SIZES.start(), *Self::MAP_SIZES.end())
    }
}

impl Default for ShadowSettings {
    fn default() -> Self {
        Self {
            enabled: true,
            method: ShadowMethod::Map,
            contact: false,
            map_size: 2048,
            format: ShadowFormat::Auto,
            pcf: Pcf::P2x2,
            constant_bias: 1.0,
            slope_bias: 1.5,
            normal_offset: 1.5,
            fit: ShadowFit::Camera,
            snap: true,
            extent_steps: 8,
            cascades: 0,
            cube_face: 0,
            depth_fit: false,
            soft: true,
        }
    }
}

/// Options fixed when a scene is uploaded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SceneOptions {
    /// Anisotropic texture filtering (1 = off). `None`: 8× on GPUs, off on CPU devices, where
    /// it more than doubles lavapipe's camera pass (demo, 1280×720: 80 → 37 ms without shadows).
    pub anisotropy: Option<u32>,
    /// Skip work that cannot change the image: draws outside the camera's view, back faces of
    /// closed double-sided meshes seen from outside, and the clear parts of lone cutout cards in
    /// the shadow passes (`crate::scene::mesh::trim`). On by default; off only to measure what it
    /// saves.
    pub culling: bool,
    /// Multisample anti-aliasing: samples per pixel of the camera pass (1, 2, 4 or 8). `None`:
    /// 4 on GPUs, 1 on CPU devices (lavapipe, where 4 samples cost
    /// `docs/speed.md`'s measured share of the frame). A count the device lacks falls to the
    /// largest it has below it (`resolved_samples`).
    pub msaa: Option<u32>,
    /// Where textures' mip chains are made: `Some(true)` on the CPU at upload
    /// (`crate::math::mips::mip_chain`, the same bytes on every device), `Some(false)` by linear
    /// blits on the device. `None`: the CPU on CPU devices (on lavapipe the blits run on the CPU
    /// too, after compiling blitter shaders that Mesa's shader cache does not keep: ~200 ms of
    /// every start), blits on GPUs.
    pub cpu_mips: Option<bool>,
    /// Shade draws of triangles smaller than llvmpipe's 4×4 shading block deferred
    /// (`crate::render::passes::deferred`: a G-buffer, then each covered pixel shaded once). `None`: on
    /// CPU devices at one sample per pixel, off on GPUs (which shade 2×2 quads in hardware).
    pub deferred: Option<bool>,
    /// Draw small receivers (a ground) without the shadow lookup where no caster can shadow them
    /// (`crate::render::passes::receivers`: the same image; llvmpipe runs the lookup even where a
    /// branch skips it). `None`: on for CPU devices, off on GPUs (whose branches skip it).
    pub receiver_split: Option<bool>,
    /// Reuse shadow-map layers across frames (`crate::render::passes::shadow_cache`): a layer whose
    /// light matrix, area and static casters are those of the last frame is not redrawn, and
    /// only moving casters (animated or deforming) are drawn over a cached copy of the static
    /// ones. The same image to the bit. Off by default (each `render` then measures the whole
    /// shadow pass); the viewer and image sequences turn it on.
    pub shadow_cache: bool,
    /// KTX2 textures (`KHR_texture_basisu`) kept block-compressed on the device: each of the
    /// file's own mip levels transcoded to BC7 (a quarter of RGBA8's memory and bandwidth).
    /// `None`: on where the device samples BC7 and is a GPU; off on CPU devices, where lavapipe
    /// decodes a block on every fetch (`docs/compressed-gltf.md` has the figures). Off, or where
    /// the device has no BC7, the levels are transcoded to RGBA8. Either way the file's mips are
    /// kept; a file with one level gets a chain made as for any image (RGBA8).
    pub block_compressed: Option<bool>,
}

impl Default for SceneOptions {
    fn default() -> Self {
        Self {
            anisotropy: None,
            culling: true,
            msaa: None,
            cpu_mips: None,
            deferred: None,
            receiver_split: None,
            shadow_cache: false,
            block_compressed: None,
        }
    }
}

/// What the plan needs to know of a device, as plain values (`render::device_facts` reads them
/// from a Vulkan context): the plan never sees the device itself.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeviceFacts {
    /// A CPU device (lavapipe): the defaults that pay there differ.
    pub cpu: bool,
    /// Sample counts (bit n set: 2ⁿ samples) that colour and depth attachments both support.
    pub sample_counts: u32,
    /// Whether the deferred path's formats work: D32_SFLOAT_S8_UINT as a depth-stencil
    /// attachment, R32G32B32A32_SFLOAT as a colour attachment and sampled image.
    pub deferred_formats: bool,
    /// The largest sampler anisotropy, None when the feature is off.
    pub max_anisotropy: Option<f32>,
    /// Whether BC7 (sRGB and linear) can be sampled with linear filtering and uploaded.
    pub bc7: bool,
}

impl SceneOptions {
    /// The MSAA sample count to use on the device: `msaa` (or the device class's default)
    /// rounded down to a count its colour and depth attachments both support.
    pub fn resolved_samples(&self, device: &DeviceFacts) -> u32 {
        let wanted = self
            .msaa
            .unwrap_or(if device.cpu { 1 } else { 4 })
            .clamp(1, 64);
        // The largest power of two not above `wanted`, then down to what the device has.
        let mut n = 1u32 << wanted.ilog2();
        while n > 1 && device.sample_counts & n == 0 {
            n /= 2;
        }
        n.max(1)
    }

    /// Whether KTX2 textures are uploaded as BC7 on the device (`block_compressed`, or its
    /// default, where the device has BC7).
    pub fn resolved_block_compressed(&self, device: &DeviceFacts) -> bool {
        self.block_compressed.unwrap_or(!device.cpu) && device.bc7
    }

    /// Whether mip chains are made on the CPU on the device (`cpu_mips`, or its default).
    pub fn resolved_cpu_mips(&self, device: &DeviceFacts) -> bool {
        self.cpu_mips.unwrap_or(device.cpu)
    }

    /// Whether micro-triangle draws may be shaded deferred on the device (`deferred`, or its
    /// default; the camera pass also needs one sample per pixel).
    pub fn resolved_deferred(&self, device: &DeviceFacts) -> bool {
        self.deferred.unwrap_or(device.cpu) && device.deferred_formats
    }

    /// Whether small receivers are drawn unshadowed beyond the casters' reach on the device
    /// (`receiver_split`, or its default).
    pub fn resolved_receiver_split(&self, device: &DeviceFacts) -> bool {
        self.receiver_split.unwrap_or(device.cpu)
    }

    /// The anisotropy to use on the device (1.0 = off), clamped to what it supports.
    pub fn resolved_anisotropy(&self, device: &DeviceFacts) -> f32 {
        let Some(max) = device.max_anisotropy else {
            return 1.0;
        };
        let wanted = self
            .anisotropy
            .unwrap_or(if device.cpu { 1 } else { 8 })
            .max(1) as f32;
        wanted.min(max.max(1.0))
    }
}

impl std::str::FromStr for Pcf {
    type Err = String;

    /// `none`, `2x2`, `3x3` or `5x5`.
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim().to_ascii_lowercase().as_str() {
            "none" => Ok(Pcf::None),
            "2x2" => Ok(Pcf::P2x2),
            "3x3" => Ok(Pcf::P3x3),
            "5x5" => Ok(Pcf::P5x5),
            _ => Err(format!("filter '{s}' is not none, 2x2, 3x3 or 5x5")),
        }
    }
}
