//! What a ray hit looks like: textures sampled with the file's samplers, alpha, normals, the
//! shading of a hit and what blends over it.

use super::*;
use crate::reference::bvh::Hit;
use glam::{Vec2, Vec3, Vec4};
use umbra::math::ray::Ray;
use umbra::plan::{Ambient, FramePlan};
use umbra::scene::{AlphaMode, Filter, Sampler, Texture, TextureRef};

/// A hit as a receiver ([`ReferenceScene::receiver`]).
pub(super) struct Receiver {
    /// The surface point, as the GPU interpolates it.
    pub p: Vec3,
    /// How far its shadow rays start off it.
    pub offset: f32,
    /// The geometric normal, facing the viewer.
    pub ng: Vec3,
    /// The interpolated normal, flipped where the face is seen from behind.
    pub n_geo: Vec3,
    /// Whether the shading normals flipped.
    pub flipped: bool,
}

/// The interpolated TEXCOORD_0, TEXCOORD_1 and COLOR_0 at hit `h` on the triangle whose first
/// index is `first` (zeros without texture coordinates, white without colours).
pub(super) fn surface_inputs(
    prim: &umbra::scene::Primitive,
    first: usize,
    h: &Hit,
) -> ([Vec2; 2], Vec4) {
    let i = [0, 1, 2].map(|k| prim.indices[first + k] as usize);
    let w = [1.0 - h.u - h.v, h.u, h.v];
    let uv0 = |v: usize| prim.uvs.get(v).copied().unwrap_or_default();
    let (mut uvs, mut color) = ([Vec2::ZERO; 2], Vec4::ZERO);
    for (v, w) in i.into_iter().zip(w) {
        uvs[0] += uv0(v) * w;
        uvs[1] += prim.uv1(v) * w;
        color += prim.color(v) * w;
    }
    (uvs, color)
}

pub(super) fn srgb_encode(c: f32) -> u8 {
    (umbra::math::tonemap::linear_to_srgb(c.clamp(0.0, 1.0)) * 255.0).round() as u8
}

impl<'a> ReferenceScene<'a> {
    pub(super) fn texel(&self, t: &Texture, s: &Sampler, x: i64, y: i64, srgb: bool) -> Vec4 {
        let (w, h) = (t.width as i64, t.height as i64);
        let (x, y) = (s.wrap_u.texel(x, w), s.wrap_v.texel(y, h));
        let i = ((y * w + x) * 4) as usize;
        let px = &t.rgba[i..i + 4];
        if srgb {
            Vec4::new(
                self.srgb_lut[px[0] as usize],
                self.srgb_lut[px[1] as usize],
                self.srgb_lut[px[2] as usize],
                px[3] as f32 / 255.0,
            )
        } else {
            Vec4::new(px[0] as f32, px[1] as f32, px[2] as f32, px[3] as f32) / 255.0
        }
    }

    /// Sample of mip 0 at `uv` after the slot's texture transform, with the texture's sampler: its magnification filter (nearest or
    /// bilinear) and wrap modes (decoded from sRGB when `srgb`). Mip 0 only: the reference has
    /// no pixel footprint, so minification filters and mipmaps are not modelled.
    /// `uvs` are the hit's TEXCOORD_0 and TEXCOORD_1; the slot reads its own set.
    pub(super) fn sample(
        &self,
        tex: Option<TextureRef>,
        uvs: [Vec2; 2],
        srgb: bool,
        default: Vec4,
    ) -> Vec4 {
        let Some((t, s, uv)) = tex.and_then(|r| {
            Some((
                self.scene.textures.get(r.texture)?,
                r.sampler,
                r.transform.apply(uvs[(r.tex_coord as usize).min(1)]),
            ))
        }) else {
            return default;
        };
        let x = uv.x * t.width as f32;
        let y = uv.y * t.height as f32;
        if s.mag == Filter::Nearest {
            return self.texel(t, &s, x.floor() as i64, y.floor() as i64, srgb);
        }
        let (x, y) = (x - 0.5, y - 0.5);
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let a = self
            .texel(t, &s, x0, y0, srgb)
            .lerp(self.texel(t, &s, x0 + 1, y0, srgb), fx);
        let b = self
            .texel(t, &s, x0, y0 + 1, srgb)
            .lerp(self.texel(t, &s, x0 + 1, y0 + 1, srgb), fx);
        a.lerp(b, fy)
    }

    /// The material of the triangle hit (None: the default material).
    pub(super) fn material_of(&self, h: &Hit) -> Option<&umbra::scene::Material> {
        let r = self.refs[h.triangle as usize];
        let prim = &self.scene.meshes[r.mesh as usize].primitives[r.primitive as usize];
        self.scene.materials.get(prim.material)
    }

    /// Base-colour alpha (factor × texture) at hit `h`.
    pub(super) fn alpha_at(&self, h: &Hit) -> f32 {
        let r = self.refs[h.triangle as usize];
        let prim = &self.scene.meshes[r.mesh as usize].primitives[r.primitive as usize];
        let Some(mat) = self.scene.materials.get(prim.material) else {
            return 1.0;
        };
        let (uvs, color) = surface_inputs(prim, r.first as usize, h);
        let tex = mat.base_color_texture;
        color.w * mat.base_color.w * self.sample(tex, uvs, true, Vec4::ONE).w
    }

    /// Whether the surface hit is unlit (KHR_materials_unlit).
    pub(super) fn unlit(&self, h: &Hit) -> bool {
        self.material_of(h).is_some_and(|m| m.unlit)
    }

    /// `rgb`, the shading of hit `h`, blended over what lies behind it when its material is
    /// blended (the GPU's over operator: a·rgb + (1 − a)·behind).
    pub(super) fn blend_behind(
        &self,
        plan: &FramePlan,
        ray: &Ray,
        h: &Hit,
        rgb: Vec3,
        ambient: Ambient,
        layers: u32,
    ) -> Vec3 {
        if layers >= MAX_BLEND_LAYERS
            || self.material_of(h).map(|m| m.alpha_mode) != Some(AlphaMode::Blend)
        {
            return rgb;
        }
        let a = self.alpha_at(h).clamp(0.0, 1.0);
        if a >= 1.0 {
            return rgb;
        }
        // Past this surface: a relative step so that the same triangle is not hit again.
        let behind = self.radiance(
            plan,
            ray,
            h.t * (1.0 + 1e-5) + self.surface_point(h).1,
            ambient,
            layers + 1,
        );
        rgb * a + behind * (1.0 - a)
    }

    /// The world vertices of the triangle hit.
    fn world_vertices(&self, h: &Hit) -> [Vec3; 3] {
        let r = self.refs[h.triangle as usize];
        let prim = &self.scene.meshes[r.mesh as usize].primitives[r.primitive as usize];
        let world_from_model = self.matrices[r.instance as usize];
        [0, 1, 2].map(|k| {
            world_from_model
                .transform_point3(prim.positions[prim.indices[r.first as usize + k] as usize])
        })
    }

    /// The surface point of a hit and how far its shadow rays start off it. The point is its
    /// triangle's vertices weighted by the hit's barycentrics, as the GPU interpolates it: off
    /// the plane by units in the last place of the triangle's coordinates, whatever the ray's
    /// length (the ray's `at(t)` errs with the distance from the eye).
    pub(super) fn surface_point(&self, h: &Hit) -> (Vec3, f32) {
        let pw = self.world_vertices(h);
        let p = pw[0] * (1.0 - h.u - h.v) + pw[1] * h.u + pw[2] * h.v;
        let n = (pw[1] - pw[0]).cross(pw[2] - pw[0]).normalize_or(Vec3::Y);
        let m = self.refs[h.triangle as usize].magnitudes;
        (p, umbra::math::ray::ray_offset(m, n, p))
    }

    /// Whether another face that stops shadow rays lies where hit `h` of `ray` does (within
    /// 10⁻⁶ of its distance) and the shown light judges it otherwise than `vis`
    /// ([`ReferenceFrame::coincident`]).
    pub(super) fn coincident(&self, plan: &FramePlan, ray: &Ray, h: &Hit, vis: bool) -> bool {
        let Some(i) = plan.shadow_light else {
            return false;
        };
        let (near, far) = (h.t * (1.0 - 1e-6), h.t * (1.0 + 1e-6));
        self.bvh
            .intersect_where(ray, near, far, &|o: &Hit| {
                o.triangle != h.triangle && self.stops(o, true)
            })
            .is_some_and(|o| self.centre_visible(plan, i, &self.receiver(ray, &o)) != vis)
    }

    /// Hit `h` of `ray` as a receiver, the one step every judgement of it shares (`render`,
    /// `probe`, `pick`, the coincidence test): its surface point and shadow-ray offset, its
    /// geometric normal turned to the viewer and its interpolated normal flipped as the GPU flips
    /// it ([`face_viewer`](super::rays::face_viewer)).
    pub(super) fn receiver(&self, ray: &Ray, h: &Hit) -> Receiver {
        let (ng, n_geo) = self.hit_normals(h);
        let (ng, flipped) = face_viewer(ng, n_geo, self.sides(h), ray.dir);
        let (p, offset) = self.surface_point(h);
        Receiver {
            p,
            offset,
            ng,
            n_geo: if flipped { -n_geo } else { n_geo },
            flipped,
        }
    }

    /// Whether the hit's instance mirrors (a negative determinant: its front faces wind
    /// clockwise, as the GPU draws them, `DrawRange::front_face`) and whether its material is
    /// double-sided ([`face_viewer`](super::rays::face_viewer)).
    pub(super) fn sides(&self, h: &Hit) -> (bool, bool) {
        let r = self.refs[h.triangle as usize];
        let mirrored =
            glam::Mat3::from_mat4(self.matrices[r.instance as usize]).determinant() < 0.0;
        (
            mirrored,
            self.material_of(h).is_some_and(|m| m.double_sided),
        )
    }

    /// Geometric and interpolated normals (world space, as stored: not yet turned to the viewer)
    /// at a hit.
    pub(super) fn hit_normals(&self, h: &Hit) -> (Vec3, Vec3) {
        let r = self.refs[h.triangle as usize];
        let prim = &self.scene.meshes[r.mesh as usize].primitives[r.primitive as usize];
        let idx = [0, 1, 2].map(|k| prim.indices[r.first as usize + k] as usize);
        let pw = self.world_vertices(h);
        let ng = (pw[1] - pw[0]).cross(pw[2] - pw[0]).normalize_or(Vec3::Y);
        if prim.normals.len() != prim.positions.len() {
            return (ng, ng);
        }
        let w = Vec3::new(1.0 - h.u - h.v, h.u, h.v);
        let n =
            prim.normals[idx[0]] * w.x + prim.normals[idx[1]] * w.y + prim.normals[idx[2]] * w.z;
        (
            ng,
            (self.normal_mats[r.instance as usize] * n).normalize_or(ng),
        )
    }

    /// The linear colour seen along `ray` beyond `t_min`: the first surface's shading, and where
    /// it is blended, that over what lies behind it (up to `MAX_BLEND_LAYERS` blended surfaces);
    /// the background where nothing is hit.
    pub(super) fn radiance(
        &self,
        plan: &FramePlan,
        ray: &Ray,
        t_min: f32,
        ambient: Ambient,
        layers: u32,
    ) -> Vec3 {
        let Some(h) = self.intersect_from(ray, t_min) else {
            return plan.background_along(ray.dir);
        };
        let (_, _, rgb) = self.shade(plan, ray, &h, ambient);
        let rgb = plan.display_surface(rgb, self.unlit(&h));
        self.blend_behind(plan, ray, &h, rgb, ambient, layers)
    }
}
