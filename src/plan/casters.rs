//! What the shadow pass draws for one view: its casters, the texels they touch, and the
//! viewpoint their faces are tested against.

use super::input::PlanScene;
use crate::math::Aabb;
use glam::{Mat4, Vec3, Vec4};

/// What a draw's faces are tested against when clusters are skipped.
#[derive(Clone, Copy, Debug)]
pub enum Viewpoint {
    /// A perspective eye (camera, spot light) at this world position.
    Eye(Vec3),
    /// An orthographic view (directional light) looking along this world direction.
    Along(Vec3),
}

/// True when a flat primitive on `plane` (`(n, w)`, unit `n`) hides nothing from `from`: the
/// viewpoint and the whole scene (bounds `scene`) lie on one closed side of the plane, and a
/// segment from a point to the viewpoint never leaves that side (a half-space is convex), so it
/// never meets the primitive except at its own end. Seen from a light, such a caster shadows
/// nothing (the shadow pass skips a ground plane with nothing under it, the largest caster of most
/// scenes); seen from the camera, it occludes nothing (the camera pass draws it after the rest, so
/// the early depth test rejects its hidden fragments). Scene parts within 1e-5 of the scene's
/// diagonal behind the plane still count as in front (a model resting on the ground), a choice
/// that can only matter for geometry sunk that little and seen from beneath the plane.
pub fn flat_hides_nothing(plane: Vec4, from: Viewpoint, scene: &Aabb) -> bool {
    let n = plane.truncate();
    let light_side = match from {
        Viewpoint::Along(d) => -n.dot(d.normalize_or_zero()),
        Viewpoint::Eye(p) => n.dot(p) + plane.w,
    };
    // Edge-on to the light, or the light on the plane: keep it (cheap, and no sign to trust).
    if light_side.abs() <= 1e-6 || !light_side.is_finite() {
        return false;
    }
    let s = light_side.signum();
    let tolerance = 1e-5 * scene.diagonal();
    scene
        .corners()
        .iter()
        .all(|c| s * (n.dot(*c) + plane.w) >= -tolerance)
}

/// A rectangle of a shadow-map layer, in texels: its corner and size.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TexelRect {
    /// First column.
    pub x: u32,
    /// First row.
    pub y: u32,
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
}

/// The casters one frame draws into the shadow map, and the texels they can touch.
#[derive(Clone, Debug)]
pub struct CasterPlan {
    /// Indices into `GpuScene::draws`.
    pub draws: Vec<usize>,
    /// The texels the pass clears and draws (the casters' rectangle grown by twice the lookup
    /// reach, so every texel a lookup inside `lookup` reads is written this frame).
    pub area: TexelRect,
    /// Texel rectangle `(x0, y0, x1, y1)` outside which a lookup's footprint meets no caster
    /// texel (the casters' rectangle grown by the reach): such lookups are lit without a read.
    pub lookup: Vec4,
    /// The view's light (clusters facing away from it are not drawn).
    pub light: Viewpoint,
    /// Side in texels of the view's square (at its layer's origin).
    pub size: u32,
}

impl Default for CasterPlan {
    /// No casters: one texel cleared, every lookup lit.
    fn default() -> Self {
        Self {
            draws: Vec::new(),
            area: TexelRect {
                x: 0,
                y: 0,
                width: 1,
                height: 1,
            },
            lookup: Vec4::new(1.0, 1.0, -1.0, -1.0),
            light: Viewpoint::Along(Vec3::NEG_Y),
            size: 1,
        }
    }
}

/// The light-clip x, y extent `[x0, y0, x1, y1]` of a caster with world bounds `b`, or None when
/// it cannot land inside the light's view (outside x, y in [−1, 1] or entirely beyond the far
/// plane). Near-plane overshoot is kept: depth clamp pancakes it. A box reaching behind a
/// perspective light's eye gets the whole view.
pub fn caster_extent(light_clip_from_world: &Mat4, b: &Aabb) -> Option<[f32; 4]> {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for c in b.corners() {
        let p = *light_clip_from_world * Vec4::new(c.x, c.y, c.z, 1.0);
        if p.w <= 1e-12 {
            return Some([-1.0, -1.0, 1.0, 1.0]);
        }
        let q = p.truncate() / p.w;
        lo = lo.min(q);
        hi = hi.max(q);
    }
    let visible = hi.x >= -1.0 && lo.x <= 1.0 && hi.y >= -1.0 && lo.y <= 1.0 && hi.z >= 0.0;
    visible.then_some([lo.x, lo.y, hi.x, hi.y])
}

/// Chooses the casters of a frame: those whose bounds reach the light's view, less flat casters
/// with nothing behind them (`flat_hides_nothing`). `reach` is how many texels from its
/// centre a lookup reads (PCF half-width + 1); `full` clears the whole map (the map debug view).
pub(crate) fn plan_casters(
    scene: &PlanScene,
    light_clip_from_world: &Mat4,
    light: Viewpoint,
    size: u32,
    reach: u32,
    full: bool,
) -> CasterPlan {
    let mut plan = CasterPlan {
        light,
        size,
        ..CasterPlan::default()
    };
    let mut ndc = [
        f32::INFINITY,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::NEG_INFINITY,
    ];
    for (i, bounds) in scene.receivers.iter().enumerate() {
        let Some(e) = caster_extent(light_clip_from_world, bounds) else {
            continue;
        };
        let plane = scene.planes.get(i).copied().flatten();
        if plane.is_some_and(|pl| flat_hides_nothing(pl, light, scene.bounds)) {
            continue;
        }
        plan.draws.push(i);
        ndc = [
            ndc[0].min(e[0]),
            ndc[1].min(e[1]),
            ndc[2].max(e[2]),
            ndc[3].max(e[3]),
        ];
    }
    let s = size as f32;
    let (x0, x1) = ((ndc[0] * 0.5 + 0.5) * s, (ndc[2] * 0.5 + 0.5) * s);
    // Texel rows grow downwards: v = 0.5 − 0.5·y.
    let (y0, y1) = ((0.5 - ndc[3] * 0.5) * s, (0.5 - ndc[1] * 0.5) * s);
    // One texel of slack for rasterisation rules, then the reach.
    let grow = |a: f32, b: f32, by: f32| ((a - 1.0 - by).max(0.0), (b + 1.0 + by).min(s));
    let empty = plan.draws.is_empty() || !(x0 <= x1 && y0 <= y1);
    let r = reach as f32;
    plan.lookup = if empty {
        Vec4::new(1.0, 1.0, -1.0, -1.0) // empty: every lookup is lit
    } else {
        let ((lx0, lx1), (ly0, ly1)) = (grow(x0, x1, r), grow(y0, y1, r));
        Vec4::new(lx0, ly0, lx1, ly1)
    };
    let ((ax0, ax1), (ay0, ay1)) = if full {
        ((0.0, s), (0.0, s))
    } else if empty {
        ((0.0, 1.0), (0.0, 1.0))
    } else {
        (grow(x0, x1, 2.0 * r + 1.0), grow(y0, y1, 2.0 * r + 1.0))
    };
    let (ax0, ay0) = (ax0.floor() as u32, ay0.floor() as u32);
    let (ax1, ay1) = (
        (ax1.ceil() as u32).max(ax0 + 1),
        (ay1.ceil() as u32).max(ay0 + 1),
    );
    plan.area = TexelRect {
        x: ax0,
        y: ay0,
        width: ax1 - ax0,
        height: ay1 - ay0,
    };
    plan
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn caster_culling() {
        let m = crate::math::projection::orthographic_reversed(-1.0, 1.0, -1.0, 1.0, 0.0, 10.0);
        let e = caster_extent(
            &m,
            &Aabb::new(Vec3::new(-0.5, -0.5, -5.0), Vec3::new(0.5, 0.5, -4.0)),
        );
        assert_eq!(e, Some([-0.5, -0.5, 0.5, 0.5]));
        // Outside in x.
        assert!(caster_extent(
            &m,
            &Aabb::new(Vec3::new(2.0, -0.5, -5.0), Vec3::new(3.0, 0.5, -4.0))
        )
        .is_none());
        // Nearer than the near plane (depth > 1): kept, depth clamp flattens it.
        assert!(caster_extent(
            &m,
            &Aabb::new(Vec3::new(-0.5, -0.5, 1.0), Vec3::new(0.5, 0.5, 2.0))
        )
        .is_some());
        // Beyond the far plane: culled.
        assert!(caster_extent(
            &m,
            &Aabb::new(Vec3::new(-0.5, -0.5, -20.0), Vec3::new(0.5, 0.5, -15.0))
        )
        .is_none());
    }

    #[test]
    fn flat_casters_with_nothing_behind_them() {
        let ground = Vec4::new(0.0, 1.0, 0.0, 0.0); // y = 0, facing +y
        let above = Aabb::new(Vec3::new(-10.0, 0.0, -10.0), Vec3::new(10.0, 5.0, 10.0));
        let sun = Viewpoint::Along(Vec3::new(0.3, -1.0, 0.2));
        assert!(flat_hides_nothing(ground, sun, &above));
        // The plane's normal may point either way: the light's side decides.
        assert!(flat_hides_nothing(-ground, sun, &above));
        // Something below the ground: it may be shadowed by the ground.
        let below = Aabb::new(Vec3::new(-10.0, -1.0, -10.0), Vec3::new(10.0, 5.0, 10.0));
        assert!(!flat_hides_nothing(ground, sun, &below));
        // A sun from below: the scene is on the dark side, the plane shadows it.
        let under = Viewpoint::Along(Vec3::new(0.0, 1.0, 0.0));
        assert!(!flat_hides_nothing(ground, under, &above));
        // A grazing sun exactly in the plane: kept.
        let grazing = Viewpoint::Along(Vec3::X);
        assert!(!flat_hides_nothing(ground, grazing, &above));
        // A spot above the ground, and one below it.
        let lamp = Viewpoint::Eye(Vec3::new(0.0, 4.0, 0.0));
        assert!(flat_hides_nothing(ground, lamp, &above));
        let cellar = Viewpoint::Eye(Vec3::new(0.0, -4.0, 0.0));
        assert!(!flat_hides_nothing(ground, cellar, &above));
        // A wall at x = 2 with the scene on both sides casts.
        let wall = Vec4::new(1.0, 0.0, 0.0, -2.0);
        assert!(!flat_hides_nothing(wall, sun, &above));
    }
}
