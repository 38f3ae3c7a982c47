//! Rays: the primary ray of a pixel, shadow rays and what stops them, the caster search.

use super::surface::Receiver;
use super::*;
use crate::reference::bvh::Hit;
use glam::{Vec2, Vec3, Vec4};
use umbra::math::projection::pixel_to_ndc;
use umbra::math::ray::Ray;
use umbra::plan::FramePlan;
use umbra::scene::{AlphaMode, LightKind, BLEND_SHADOW_CUTOFF};

/// The primary ray through image position (x, y) of `plan`'s camera (clip → world `inv`): from
/// the eye through the pixel for a perspective camera, from the pixel on the near plane along the
/// view for an orthographic one (parallel rays).
pub(super) fn primary_ray(
    plan: &FramePlan,
    inv: &glam::Mat4,
    x: f32,
    y: f32,
    w: u32,
    h: u32,
) -> Ray {
    let n = pixel_to_ndc(x, y, w, h);
    let at = |depth: f32| {
        let p = *inv * Vec4::new(n.x, n.y, depth, 1.0);
        p.truncate() / p.w
    };
    if plan.orthographic {
        let near = at(1.0);
        return Ray::new(near, (at(0.5) - near).normalize_or(Vec3::NEG_Z));
    }
    let eye = plan.camera_position;
    Ray::new(eye, (at(1e-3) - eye).normalize_or(Vec3::NEG_Z))
}

/// Turns a hit's geometric normal `ng` (the counter-clockwise one, from its world vertices)
/// towards the viewer along `dir`; the returned flag says whether its shading normals (`n`, the
/// interpolated one) flip. A double-sided material's back face flips them, as glTF asks and as the
/// shader does on `front_facing`, whatever way they point; a `mirrored` instance (negative
/// determinant) winds its front faces clockwise. A single-sided material's back face is culled
/// on the GPU; where the reference's primary ray still grazes one at a silhouette, its normals
/// turn to the viewer only if they face away, standing in for the front face beside it.
pub(super) fn face_viewer(
    ng: Vec3,
    n: Vec3,
    (mirrored, double_sided): (bool, bool),
    dir: Vec3,
) -> (Vec3, bool) {
    let away = ng.dot(dir) > 0.0;
    let flip = if double_sided {
        away != mirrored
    } else {
        away && n.dot(dir) > 0.0
    };
    (if away { -ng } else { ng }, flip)
}

/// Light `l` seen from point `p`: unit direction towards it, distance (∞ for a directional
/// light) and radiance arriving (inverse square and the spot cone applied).
pub(super) fn light_at(l: &umbra::scene::Light, p: Vec3) -> (Vec3, f32, Vec3) {
    match l.kind {
        LightKind::Directional => (
            -l.direction.normalize_or(Vec3::NEG_Y),
            f32::INFINITY,
            l.color * l.intensity,
        ),
        _ => {
            let d = l.position - p;
            let r2 = d.length_squared().max(1e-8);
            let dir = d / r2.sqrt();
            let mut rad = l.color * l.intensity / r2 * l.range_window(r2.sqrt());
            let cd = (-dir).dot(l.direction.normalize_or(Vec3::NEG_Y));
            rad *= l.cone_attenuation(cd);
            (dir, r2.sqrt(), rad)
        }
    }
}

/// Sample `k` of `n` on the unit disk: an area-uniform golden-angle spiral.
pub(super) fn spiral(k: usize, n: usize) -> Vec2 {
    let r = ((k as f32 + 0.5) / n as f32).sqrt();
    let a = k as f32 * 2.399_963_2;
    Vec2::new(r * a.cos(), r * a.sin())
}

impl<'a> ReferenceScene<'a> {
    /// Exact visibility of world point `p` (its shadow rays' offset `offset`, geometric normal
    /// `ng`, facing normal `n`) from light `i`: whether its centre is visible, the fraction of its
    /// emitter that is (the same for a punctual light), the direction towards it and the radiance
    /// arriving.
    pub(super) fn visible(
        &self,
        plan: &FramePlan,
        i: usize,
        (p, offset): (Vec3, f32),
        ng: Vec3,
        n_facing: Vec3,
    ) -> (bool, f32, Vec3, Vec3) {
        let l = &plan.lights[i];
        let (dir, dist, radiance) = light_at(l, p);
        let facing = n_facing.dot(dir) > 0.0;
        if !facing {
            return (false, 0.0, dir, radiance);
        }
        if !plan.is_shadowed(i) {
            return (true, 1.0, dir, radiance);
        }
        let centre = !self.occluded((p, offset), ng, dir, dist);
        let size = umbra::plan::soft_size(l);
        if size <= 0.0 {
            return (centre, if centre { 1.0 } else { 0.0 }, dir, radiance);
        }
        // The emitter's disk across the direction to it: the sun's directions within its
        // angular radius (tan = size), a sphere light's disk of radius `size`.
        let (e1, e2) = dir.any_orthonormal_pair();
        let open = (0..AREA_SAMPLES)
            .filter(|&k| {
                let u = spiral(k, AREA_SAMPLES);
                let (d, t) = match l.kind {
                    LightKind::Directional => (
                        (dir + (e1 * u.x + e2 * u.y) * size).normalize(),
                        f32::INFINITY,
                    ),
                    _ => {
                        let to = l.position + (e1 * u.x + e2 * u.y) * size - p;
                        let t = to.length();
                        (to / t.max(1e-20), t)
                    }
                };
                !self.occluded((p, offset), ng, d, t)
            })
            .count();
        (centre, open as f32 / AREA_SAMPLES as f32, dir, radiance)
    }

    /// Whether light `i`'s centre reaches receiver `r` as the frame judges it: facing it, and
    /// unoccluded where the plan shadows that light (`visible`'s first answer, without the
    /// emitter's samples).
    pub(super) fn centre_visible(&self, plan: &FramePlan, i: usize, r: &Receiver) -> bool {
        let (dir, dist, _) = light_at(&plan.lights[i], r.p);
        r.n_geo.dot(dir) > 0.0
            && (!plan.is_shadowed(i) || !self.occluded((r.p, r.offset), r.ng, dir, dist))
    }

    /// Whether anything lies between surface point `p` (geometric normal `ng`) and a light
    /// `dist` away along `dir`.
    pub(super) fn occluded(
        &self,
        (p, offset): (Vec3, f32),
        ng: Vec3,
        dir: Vec3,
        dist: f32,
    ) -> bool {
        // Start the shadow ray off the surface by its offset, on the light's side of the true
        // face: its own triangle then lies behind it (t < 0), as on the GPU.
        let side = if ng.dot(dir) >= 0.0 { ng } else { -ng };
        let origin = p + side * offset;
        self.bvh
            .occluded_where(&Ray::new(origin, dir), 0.0, dist - offset, &|h: &Hit| {
                self.stops(h, true)
            })
    }

    /// Whether a caster of light `i` lies within `radius` of surface point `p` (its shadow rays'
    /// offset `offset`, geometric normal `ng`) across the light's direction: shadow rays start from 32 points of a disk of that
    /// radius around `p` (across the direction to the light, moved along it onto `p`'s tangent
    /// plane). A shadow map resolves
    /// casters to its lookup's reach, so a false shadow with such a caster nearby is a shadow
    /// drawn too wide, not the receiver shadowing itself.
    pub fn caster_within(
        &self,
        plan: &FramePlan,
        i: usize,
        (p, offset): (Vec3, f32),
        ng: Vec3,
        radius: f32,
    ) -> bool {
        let Some(l) = plan.lights.get(i) else {
            return false;
        };
        let (dir, _, _) = light_at(l, p);
        let cos = ng.dot(dir);
        if cos.abs() < 1e-3 {
            return false;
        }
        let side = if cos >= 0.0 { ng } else { -ng };
        let (e1, e2) = dir.any_orthonormal_pair();
        (0..32).any(|k| {
            let u = spiral(k, 32) * radius;
            let o = e1 * u.x + e2 * u.y;
            // Onto the tangent plane along the light's direction.
            let start = p + o - dir * (ng.dot(o) / cos) + side * offset;
            let (d, t) = match l.kind {
                LightKind::Directional => (dir, f32::INFINITY),
                _ => {
                    let to = l.position - start;
                    let t = to.length();
                    (to / t.max(1e-20), t)
                }
            };
            self.bvh
                .occluded_where(&Ray::new(start, d), 0.0, t - offset, &|h: &Hit| {
                    self.stops(h, true)
                })
        })
    }

    /// The nearest surface along a primary ray from `t_min` (alpha-masked texels let it
    /// through).
    pub(super) fn intersect_from(&self, ray: &Ray, t_min: f32) -> Option<Hit> {
        self.bvh
            .intersect_where(ray, t_min, f32::INFINITY, &|h: &Hit| self.stops(h, false))
    }

    /// The receiver seen through `h`, a blended texel below `BLEND_SHADOW_CUTOFF` (which
    /// neither casts nor receives): the next surface along `ray` that would stop a shadow ray.
    pub(super) fn receiver_beyond(&self, ray: &Ray, h: &Hit) -> Option<Hit> {
        self.bvh.intersect_where(
            ray,
            h.t * (1.0 + 1e-5) + self.surface_point(h).1,
            f32::INFINITY,
            &|h: &Hit| self.stops(h, true),
        )
    }

    /// The nearest surface along a primary ray.
    pub(super) fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.intersect_from(ray, 0.0)
    }

    /// Whether a hit stops a primary ray or (`shadow`) a shadow ray: always, except where the
    /// base colour's alpha (factor × texture, bilinear on mip 0 as everywhere here) is below the
    /// cutoff of an alpha-masked material (where the GPU's masked pipelines discard, camera and
    /// shadow pass alike), and, for shadow rays, below `BLEND_SHADOW_CUTOFF` on a blended one.
    pub(super) fn stops(&self, h: &Hit, shadow: bool) -> bool {
        let cutoff = match self.material_of(h).map(|m| m.alpha_mode) {
            Some(AlphaMode::Mask(c)) => c,
            Some(AlphaMode::Blend) if shadow => BLEND_SHADOW_CUTOFF,
            _ => return true,
        };
        self.alpha_at(h) >= cutoff
    }
}
