//! Scene data types.

use crate::math::Aabb;
use glam::{Mat4, Vec2, Vec3, Vec4};

/// One indexed triangle list with its vertex attributes (all arrays have `positions.len()` items).
#[derive(Clone, Debug, Default)]
pub struct Primitive {
    /// Object-space positions.
    pub positions: Vec<Vec3>,
    /// Unit normals.
    pub normals: Vec<Vec3>,
    /// Texture coordinates (TEXCOORD_0); zeros when the source had none.
    pub uvs: Vec<Vec2>,
    /// Tangents: xyz unit, w = ±1 bitangent sign (glTF convention).
    pub tangents: Vec<Vec4>,
    /// Triangle list indices into the vertex arrays.
    pub indices: Vec<u32>,
    /// Index into `Scene::materials`.
    pub material: usize,
    /// Whether the source had texture coordinates.
    pub has_uvs: bool,
    /// Vertex colours (COLOR_0, linear RGBA, multiplying the base colour); empty: white.
    pub colors: Vec<Vec4>,
    /// Second texture coordinates (TEXCOORD_1); empty: none (a slot reading set 1 reads set 0).
    pub uvs1: Vec<Vec2>,
    /// For a primitive that skins or morphs: its undeformed data, influences and targets
    /// (`positions`, `normals` and `tangents` then hold the current pose).
    pub deform: Option<Box<super::anim::Deform>>,
}

impl Primitive {
    /// The vertex colour of vertex `i` (white without COLOR_0).
    pub fn color(&self, i: usize) -> Vec4 {
        self.colors.get(i).copied().unwrap_or(Vec4::ONE)
    }

    /// TEXCOORD_1 of vertex `i` (TEXCOORD_0's without one).
    pub fn uv1(&self, i: usize) -> Vec2 {
        self.uvs1
            .get(i)
            .or_else(|| self.uvs.get(i))
            .copied()
            .unwrap_or_default()
    }
}

impl Primitive {
    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Object-space bounds.
    pub fn bounds(&self) -> Aabb {
        Aabb::from_points(self.positions.iter().copied())
    }
}

/// A mesh: several primitives drawn with one transform.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    /// Name from the file, if any.
    pub name: String,
    /// Its primitives.
    pub primitives: Vec<Primitive>,
}

/// How a material treats alpha.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AlphaMode {
    /// Alpha ignored.
    Opaque,
    /// Fragments with alpha below the cutoff are discarded.
    Mask(f32),
    /// Blended over what lies behind: drawn after the opaque and masked draws, sorted back to
    /// front per draw, without depth writes; casts a shadow where alpha ≥
    /// [`BLEND_SHADOW_CUTOFF`].
    Blend,
}

/// A blended material casts a shadow where its alpha is at least this (a mask at 0.5: a
/// half-transparent surface is treated as a full caster or none, never a partial one).
pub const BLEND_SHADOW_CUTOFF: f32 = 0.5;

/// A reference to a texture and how it is sampled.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureRef {
    /// Index into `Scene::textures`.
    pub texture: usize,
    /// Filters and wrap modes (the glTF texture's sampler).
    pub sampler: super::Sampler,
    /// KHR_texture_transform of this slot (identity without one).
    pub transform: super::UvTransform,
    /// The TEXCOORD set it reads: 0 or 1 (the textureInfo's `texCoord`, or the transform's
    /// override).
    pub tex_coord: u32,
}

impl TextureRef {
    /// Texture `texture` with the default sampler (linear, mipmapped, repeating).
    pub fn new(texture: usize) -> Self {
        Self {
            texture,
            sampler: super::Sampler::default(),
            transform: super::UvTransform::default(),
            tex_coord: 0,
        }
    }
}

/// glTF metallic-roughness material (the renderer maps it to Blinn-Phong: see `material.rs`).
#[derive(Clone, Debug)]
pub struct Material {
    /// Name from the file.
    pub name: String,
    /// Linear RGBA base colour factor.
    pub base_color: Vec4,
    /// sRGB-encoded base colour texture.
    pub base_color_texture: Option<TextureRef>,
    /// Metallic factor 0..1.
    pub metallic: f32,
    /// Roughness factor 0..1.
    pub roughness: f32,
    /// Linear texture: G = roughness, B = metallic.
    pub metallic_roughness_texture: Option<TextureRef>,
    /// Tangent-space normal map (linear).
    pub normal_texture: Option<TextureRef>,
    /// Scale applied to the normal map's x and y.
    pub normal_scale: f32,
    /// Linear emissive factor.
    pub emissive: Vec3,
    /// sRGB emissive texture.
    pub emissive_texture: Option<TextureRef>,
    /// Linear occlusion texture (red channel), scaling the ambient term.
    pub occlusion_texture: Option<TextureRef>,
    /// glTF `occlusionTexture.strength`: ambient × (1 + strength · (occlusion − 1)).
    pub occlusion_strength: f32,
    /// Alpha handling.
    pub alpha_mode: AlphaMode,
    /// Render both faces (and cast from both).
    pub double_sided: bool,
    /// KHR_materials_unlit.
    pub unlit: bool,
}

impl Default for Material {
    fn default() -> Self {
        Self {
            name: "default".into(),
            base_color: Vec4::ONE,
            base_color_texture: None,
            metallic: 0.0,
            roughness: 0.6,
            metallic_roughness_texture: None,
            normal_texture: None,
            normal_scale: 1.0,
            emissive: Vec3::ZERO,
            emissive_texture: None,
            occlusion_texture: None,
            occlusion_strength: 1.0,
            alpha_mode: AlphaMode::Opaque,
            double_sided: false,
            unlit: false,
        }
    }
}

/// An RGBA8 image. Whether it is sRGB-encoded depends on which material slot uses it.
#[derive(Clone, Debug)]
pub struct Texture {
    /// Name or URI.
    pub name: String,
    /// Width in pixels (≥ 1).
    pub width: u32,
    /// Height in pixels (≥ 1).
    pub height: u32,
    /// Row-major RGBA8 pixels, `width * height * 4` bytes.
    pub rgba: Vec<u8>,
    /// The KTX2 file (`KHR_texture_basisu`) that `rgba` is the first level of: the renderer
    /// uploads the file's own mip levels, as BC7 where `SceneOptions::block_compressed` says.
    /// `None` for every other image (its chain is made from `rgba`).
    pub ktx2: Option<std::sync::Arc<[u8]>>,
}

/// Kind of punctual light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightKind {
    /// Parallel rays along `direction`.
    Directional,
    /// Omnidirectional from `position`, 1/r² falloff.
    Point,
    /// A cone from `position` along `direction`.
    Spot {
        /// Inner cone half-angle (radians): full intensity inside.
        inner: f32,
        /// Outer cone half-angle (radians): zero outside.
        outer: f32,
    },
}

/// A light in world space.
#[derive(Clone, Copy, Debug)]
pub struct Light {
    /// Kind.
    pub kind: LightKind,
    /// World position (point, spot).
    pub position: Vec3,
    /// Unit direction the light travels (directional, spot).
    pub direction: Vec3,
    /// Linear colour.
    pub color: Vec3,
    /// Intensity I (multiplies colour; 1/r² applies to point and spot).
    pub intensity: f32,
    /// Whether it casts shadows (each casting light gets shadow views while the frame has them:
    /// `render::MAX_SHADOW_VIEWS`).
    pub casts_shadows: bool,
    /// KHR_lights_punctual `range` (point, spot): the intensity is windowed by
    /// clamp(1 − (d/range)⁴, 0, 1) and is zero beyond it; None: unlimited.
    pub range: Option<f32>,
    /// Size of the emitter, for soft shadows (PCSS): a directional light's angular diameter in
    /// radians (the sun: 0.0093), a point or spot light's radius in scene units. 0 (glTF's
    /// punctual lights, the default) casts hard shadows. Read from the glTF light's
    /// `extras.light_size` (degrees for a directional light, scene units otherwise).
    pub size: f32,
}

impl Light {
    /// The spec's distance window at distance `d` (1 without a range).
    pub fn range_window(&self, d: f32) -> f32 {
        match self.range {
            Some(r) if self.kind != LightKind::Directional => {
                (1.0 - (d / r).powi(4)).clamp(0.0, 1.0)
            }
            _ => 1.0,
        }
    }

    /// The spec's spot-cone attenuation for the cosine `cd` of the angle from the spot axis:
    /// t² with t = clamp((cd − cos outer) / max(0.001, cos inner − cos outer), 0, 1) (1 for
    /// other kinds).
    pub fn cone_attenuation(&self, cd: f32) -> f32 {
        match self.kind {
            LightKind::Spot { inner, outer } => {
                let scale = 1.0 / (inner.cos() - outer.cos()).max(0.001);
                let t = ((cd - outer.cos()) * scale).clamp(0.0, 1.0);
                t * t
            }
            _ => 1.0,
        }
    }
}

impl Light {
    /// The same light in coordinates relative to `origin` (see [`Scene::render_origin`]).
    pub fn rebased(&self, origin: Vec3) -> Self {
        Self {
            position: rebased_point(self.position, origin),
            ..*self
        }
    }

    /// A shadow-casting sun travelling along `direction`.
    pub fn sun(direction: Vec3, intensity: f32) -> Self {
        Self {
            kind: LightKind::Directional,
            position: Vec3::ZERO,
            direction: direction.try_normalize().unwrap_or(-Vec3::Y),
            color: Vec3::ONE,
            intensity,
            casts_shadows: true,
            range: None,
            size: 0.0,
        }
    }

    /// Direction of a sun at `elevation` above the horizon and `azimuth` around +Y (radians),
    /// pointing from the sun into the scene.
    pub fn sun_direction(elevation: f32, azimuth: f32) -> Vec3 {
        let (se, ce) = elevation.sin_cos();
        let (sa, ca) = azimuth.sin_cos();
        -Vec3::new(ce * sa, se, ce * ca)
    }
}

/// How a camera maps view space onto the image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Perspective with this vertical field of view (radians); the image's aspect ratio sets the
    /// horizontal one (a glTF camera's `aspectRatio` is not used).
    Perspective {
        /// Vertical field of view (radians).
        fov_y: f32,
    },
    /// Parallel projection (glTF's orthographic camera): the view volume spans ±`ymag`
    /// vertically and ±`ymag` × the image's aspect ratio horizontally, so an image of the
    /// camera's own aspect ratio (`xmag / ymag`) spans ±`xmag` exactly (as the glTF matrix does)
    /// and other images are not stretched.
    Orthographic {
        /// Half the width of the view volume in an image of aspect `xmag / ymag`.
        xmag: f32,
        /// Half the height of the view volume.
        ymag: f32,
    },
}

/// A camera: perspective or orthographic.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Camera → world (the camera looks down its −Z).
    pub world_from_view: Mat4,
    /// Its projection.
    pub projection: Projection,
    /// Near plane distance.
    pub near: f32,
    /// Far plane distance; `None` for an infinite reversed-z perspective (an orthographic
    /// camera without one reaches [`Camera::ORTHO_DEFAULT_DEPTH`] half-heights past its near
    /// plane).
    pub far: Option<f32>,
}

impl Camera {
    /// How deep, in half-heights (`ymag`), an orthographic camera without a far plane sees.
    pub const ORTHO_DEFAULT_DEPTH: f32 = 1.0e4;

    /// A perspective camera at `eye` looking at `target` (Y up; Z up if looking straight down or
    /// up).
    pub fn look_at(eye: Vec3, target: Vec3, fov_y: f32, near: f32) -> Self {
        Self {
            world_from_view: look_at_frame(eye, target),
            projection: Projection::Perspective { fov_y },
            near,
            far: None,
        }
    }

    /// An orthographic camera at `eye` looking at `target` (Y up), seeing ±`ymag` vertically
    /// from `near` to `far` in front of the eye.
    pub fn orthographic_look_at(eye: Vec3, target: Vec3, ymag: f32, near: f32, far: f32) -> Self {
        Self {
            world_from_view: look_at_frame(eye, target),
            projection: Projection::Orthographic { xmag: ymag, ymag },
            near,
            far: Some(far),
        }
    }

    /// The vertical field of view of a perspective camera (None for an orthographic one).
    pub fn fov_y(&self) -> Option<f32> {
        match self.projection {
            Projection::Perspective { fov_y } => Some(fov_y),
            Projection::Orthographic { .. } => None,
        }
    }

    /// Whether the camera projects in parallel.
    pub fn is_orthographic(&self) -> bool {
        matches!(self.projection, Projection::Orthographic { .. })
    }

    /// Half the width and height of what the camera sees at view depth `d` in an image of
    /// `aspect` (width / height).
    pub fn half_extent_at(&self, d: f32, aspect: f32) -> Vec2 {
        let h = match self.projection {
            Projection::Perspective { fov_y } => d * (fov_y * 0.5).tan(),
            Projection::Orthographic { ymag, .. } => ymag,
        };
        Vec2::new(h * aspect, h)
    }

    /// The far plane's distance: `far`, or for an orthographic camera without one its default
    /// depth; None for an infinite perspective.
    pub fn far_plane(&self) -> Option<f32> {
        match (self.far, self.projection) {
            (Some(f), _) if f > self.near => Some(f),
            (_, Projection::Orthographic { ymag, .. }) => {
                Some(self.near + Self::ORTHO_DEFAULT_DEPTH * ymag.abs().max(f32::MIN_POSITIVE))
            }
            _ => None,
        }
    }

    /// World → view.
    pub fn view_from_world(&self) -> Mat4 {
        self.world_from_view.inverse()
    }

    /// Eye position in world space.
    pub fn position(&self) -> Vec3 {
        self.world_from_view.w_axis.truncate()
    }

    /// The unit direction the camera looks along (its −Z in world space).
    pub fn forward(&self) -> Vec3 {
        self.world_from_view
            .transform_vector3(Vec3::NEG_Z)
            .normalize_or(Vec3::NEG_Z)
    }

    /// The same camera in coordinates relative to `origin` (see [`Scene::render_origin`]).
    pub fn rebased(&self, origin: Vec3) -> Self {
        Self {
            world_from_view: rebased(self.world_from_view, origin),
            ..*self
        }
    }
}

/// Camera → world of an eye at `eye` looking at `target`, Y up (Z up when looking straight down
/// or up).
fn look_at_frame(eye: Vec3, target: Vec3) -> Mat4 {
    let d = (target - eye).normalize_or_zero();
    let up = if d.cross(Vec3::Y).length_squared() < 1e-8 {
        Vec3::Z
    } else {
        Vec3::Y
    };
    Mat4::look_at_rh(eye, target, up).inverse()
}

/// `world_from_model` in coordinates relative to `origin`: the translation minus `origin`,
/// subtracted in f64 so that a transform 10⁶ units out keeps its sub-millimetre part.
pub fn rebased(world_from_model: Mat4, origin: Vec3) -> Mat4 {
    if origin == Vec3::ZERO {
        return world_from_model;
    }
    let mut m = world_from_model;
    let t = m.w_axis;
    m.w_axis = rebased_point(t.truncate(), origin).extend(t.w);
    m
}

/// `p − origin`, subtracted in f64 (see [`rebased`]).
pub fn rebased_point(p: Vec3, origin: Vec3) -> Vec3 {
    (p.as_dvec3() - origin.as_dvec3()).as_vec3()
}

/// A placed mesh.
#[derive(Clone, Copy, Debug)]
pub struct Instance {
    /// Index into `Scene::meshes`.
    pub mesh: usize,
    /// Model → world.
    pub world_from_model: Mat4,
    /// The glTF node it comes from (`Scene::node_names`), if any.
    pub node: Option<usize>,
}

/// A scene ready to render.
#[derive(Clone, Debug, Default)]
pub struct Scene {
    /// Name (file name or "demo").
    pub name: String,
    /// Meshes.
    pub meshes: Vec<Mesh>,
    /// Materials (at least one).
    pub materials: Vec<Material>,
    /// Textures.
    pub textures: Vec<Texture>,
    /// Placed meshes (flattened node hierarchy).
    pub instances: Vec<Instance>,
    /// Lights (world space).
    pub lights: Vec<Light>,
    /// Cameras from the file (world space).
    pub cameras: Vec<Camera>,
    /// Repairs and unsupported features met while loading.
    pub warnings: Vec<super::Warning>,
    /// Bounds to frame with the default camera when they differ from `bounds()` (set when a
    /// helper such as a ground plane is added).
    pub framing: Option<Aabb>,
    /// For a loaded glTF: each image's index into `textures` (`None` where it failed to load).
    pub image_textures: Vec<Option<usize>>,
    /// For a loaded glTF: every node's name (empty where it has none), by node index.
    pub node_names: Vec<String>,
    /// For a loaded glTF with animations, skins or morph targets: what moves and how
    /// ([`super::anim`]); the scene as loaded holds its rest pose.
    pub rig: Option<std::sync::Arc<super::anim::Rig>>,
    /// For a loaded glTF: what was decoded from compressed or quantized data (empty if none).
    pub compression: super::gltf::compressed::CompressionReport,
}

impl Scene {
    /// The point the GPU and the reference work relative to: the origin for a scene near it,
    /// else the centre of its bounds (when that centre is more than 4 radii from the origin).
    /// Model and light transforms are rebased on the CPU in f64 ([`rebased`]), so the f32
    /// positions the GPU computes are small wherever the scene lies; a scene 10⁶ units out is
    /// drawn with the precision it has at the origin (the `precision` stability probe).
    /// Vertex positions themselves stay as stored: a mesh whose vertices are far from its own
    /// node's origin keeps the f32 precision of its model space.
    pub fn render_origin(&self) -> Vec3 {
        let b = self.bounds();
        if b.is_empty() {
            return Vec3::ZERO;
        }
        let c = b.center();
        let radius = (b.diagonal() * 0.5).max(f32::MIN_POSITIVE);
        if c.is_finite() && c.length() > 4.0 * radius {
            c
        } else {
            Vec3::ZERO
        }
    }

    /// World-space bounds of all instances.
    pub fn bounds(&self) -> Aabb {
        self.draw_bounds()
            .iter()
            .fold(Aabb::EMPTY, |b, d| b.union(d))
    }

    /// World bounds of every draw (each instance's primitives).
    pub fn draw_bounds(&self) -> Vec<Aabb> {
        self.draw_bounds_rebased(Vec3::ZERO)
    }

    /// Bounds of every draw relative to `origin` (transforms rebased in f64, as the renderer
    /// places them).
    pub fn draw_bounds_rebased(&self, origin: Vec3) -> Vec<Aabb> {
        self.instances
            .iter()
            .flat_map(|i| {
                let m = rebased(i.world_from_model, origin);
                self.meshes[i.mesh]
                    .primitives
                    .iter()
                    .map(move |p| p.bounds().transformed(&m))
            })
            .collect()
    }

    /// Total triangles drawn (instances counted).
    pub fn triangle_count(&self) -> usize {
        self.instances
            .iter()
            .map(|i| {
                self.meshes[i.mesh]
                    .primitives
                    .iter()
                    .map(|p| p.triangle_count())
                    .sum::<usize>()
            })
            .sum()
    }

    /// Records a warning with its code (`scene::warning::FINDING_CODES`) and the JSON pointer
    /// of the object it is about (logged at debug level; front ends print the list).
    pub fn warn(&mut self, code: &'static str, pointer: impl Into<String>, msg: impl Into<String>) {
        let message = msg.into();
        log::debug!("{}: {message} [{code}]", self.name);
        self.warnings.push(super::Warning {
            code,
            pointer: pointer.into(),
            message,
        });
    }
}
