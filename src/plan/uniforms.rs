//! `#[repr(C)]` mirrors of the shader structs; their sizes are checked at compile time against the
//! sizes naga computed from the WGSL (`build.rs`), in `render::pipeline`, where both are known.

use crate::shader_consts as shaders;
use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec4};

/// Most lights the camera pass shades.
pub const MAX_LIGHTS: usize = shaders::scene::MAX_LIGHTS as usize;
/// Most shadow views (layers of the shadow map) in one frame: a directional light takes one per
/// cascade, a spot light one, a point light six (cube faces).
pub const MAX_SHADOW_VIEWS: usize = shaders::scene::MAX_SHADOW_VIEWS as usize;

/// One light as the shader sees it.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct LightUniform {
    /// xyz position, w kind (0 directional, 1 point, 2 spot).
    pub position: Vec4,
    /// xyz unit direction of travel.
    pub direction: Vec4,
    /// rgb colour × intensity.
    pub color: Vec4,
    /// x cos(inner), y cos(outer).
    pub cone: Vec4,
    /// x first shadow view (−1: casts none), y its view count (cascades; 6 cube faces for a
    /// point light).
    pub shadow: Vec4,
}

/// One shadow view (one layer of the shadow map) as the shader sees it.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct ShadowViewUniform {
    /// World → light clip.
    pub clip: Mat4,
    /// Texel rectangle (x0, y0, x1, y1) of its layer outside which a lookup's footprint meets no
    /// caster (lit without reading the map; the texels there are not cleared).
    pub rect: Vec4,
    /// x view depth where the cascade ends (the last: f32::MAX), y where blending into the next
    /// starts, z world size of a texel (directional) or per unit distance (spot, point face), w
    /// its side in texels (the square at the layer's origin it fills).
    pub cascade: Vec4,
}

impl Default for ShadowViewUniform {
    /// Never read: every lookup lit.
    fn default() -> Self {
        Self {
            clip: Mat4::IDENTITY,
            rect: Vec4::new(1.0, 1.0, -1.0, -1.0),
            cascade: Vec4::new(f32::MAX, f32::MAX, 0.0, 0.0),
        }
    }
}

/// Per-frame constants of the camera pass (`Frame` in scene.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct FrameUniform {
    /// World → clip (camera).
    pub clip_from_world: Mat4,
    /// Clip → world (its inverse, computed in double precision).
    pub world_from_clip: Mat4,
    /// Camera position.
    pub camera_position: Vec4,
    /// Ambient Ia of a surface facing up (the sky of `Ambient`).
    pub ambient_sky: Vec4,
    /// Ambient Ia of a surface facing down (the ground of `Ambient`).
    pub ambient_ground: Vec4,
    /// x map size, y normal offset (texels), z the depth view's far end, w enabled.
    pub shadow: Vec4,
    /// w: index of the light whose visibility the shadow view shows (`MAX_LIGHTS + 1` when
    /// none); xyz: the eye cascades are split from (the shadow-fitting camera's position; view
    /// depth = dot(p − eye, forward)).
    pub shadow_light: Vec4,
    /// x constant bias in shadow texels (towards the light).
    pub bias: Vec4,
    /// xyz: the shadow-fitting camera's forward direction.
    pub camera_forward: Vec4,
    /// xyz: the view camera's forward direction; w: 1 for an orthographic camera (every
    /// fragment is seen along xyz).
    pub eye_forward: Vec4,
    /// x view mode, y PCF taps per side (0 = nearest), z hardware compare, w light count.
    pub modes: [u32; 4],
    /// x exposure (linear scale), y tone-mapping operator (`Tonemap::shader_value`), z the scale
    /// of unlit colours and w 1 when they are shown as authored (× z, no tone curve; the
    /// automatic exposure), 0 when exposed and tone-mapped like lit ones.
    pub output: Vec4,
    /// Lights.
    pub lights: [LightUniform; MAX_LIGHTS],
    /// Shadow views; layer i of the shadow map belongs to view i.
    pub views: [ShadowViewUniform; MAX_SHADOW_VIEWS],
}

/// Material constants (`Material` in scene.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct MaterialUniform {
    /// Base colour factor.
    pub base_color: Vec4,
    /// rgb emissive, w normal scale.
    pub emissive: Vec4,
    /// x metallic, y roughness, z occlusion strength (0 without an occlusion texture; it is
    /// packed into the metallic-roughness texture's red channel), w unlit.
    pub params: Vec4,
    /// x alpha cutoff.
    pub extra: Vec4,
    /// KHR_texture_transform rows per slot (base colour, normal, metallic-roughness, emissive):
    /// u' = uv[2i].xyz · (u, v, 1), v' = uv[2i+1].xyz · (u, v, 1).
    pub uv: [Vec4; 8],
}

/// Per-draw immediates of the camera pass.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct SceneImmediates {
    /// Model → world.
    pub world_from_model: Mat4,
    /// Normal matrix column 0; w = sign of the determinant.
    pub normal_x: Vec4,
    /// Normal matrix column 1; w = 1 to tint the draw (the viewer's picked primitive).
    pub normal_y: Vec4,
    /// Normal matrix column 2; w = the draw's instance + 1 (the id the AOV outputs write).
    pub normal_z: Vec4,
}

/// Per-draw immediates of the shadow pass.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct ShadowImmediates {
    /// World → light clip.
    pub light_clip_from_world: Mat4,
    /// Model → world.
    pub world_from_model: Mat4,
}

impl SceneImmediates {
    /// Immediates for a model transform (normal matrix = inverse transpose of its 3×3).
    pub fn new(world_from_model: Mat4) -> Self {
        let m3 = glam::Mat3::from_mat4(world_from_model);
        let det = m3.determinant();
        let nm = if det.abs() > 1e-30 {
            m3.inverse().transpose()
        } else {
            m3
        };
        let sign = if det < 0.0 { -1.0 } else { 1.0 };
        Self {
            world_from_model,
            normal_x: nm.x_axis.extend(sign),
            normal_y: nm.y_axis.extend(0.0),
            normal_z: nm.z_axis.extend(0.0),
        }
    }

    /// These immediates for a draw of scene instance `instance` (its id in the AOV outputs,
    /// `normal_z.w`; exact as a float below 2^24).
    pub fn with_instance(mut self, instance: usize) -> Self {
        self.normal_z.w = (instance + 1) as f32;
        self
    }
}
