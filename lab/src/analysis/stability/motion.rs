//! Stability in motion: the camera stands still while the world moves. Two probes:
//! - *moving caster*: the scene's own first animation when it has one (Fox walking), else a box
//!   added to it that crosses the scene through the cascade splits, rises towards the sun (close
//!   to the light) and leaves the scene's bounds;
//! - *sun arc*: a time-of-day arc, the sun climbing from 10° to 70° and turning 60° about the
//!   vertical over the still scene.
//!
//! Flicker is the fraction of still receiver points (pixels seeing the same surface at the same
//! depth in two consecutive frames) whose shadow classification flips between the frames while
//! their exact visibility, ray-cast for each frame, does not; also counted away from edges (points
//! beyond `EDGE_PIXELS` of an exact shadow boundary in both frames). Flown with maps fitted
//! afresh per frame (as stills) and held (`View::shadow_hold`, as the viewer renders), and with
//! exact and hybrid shadows.

use super::{fraction, shadow_frame};
use crate::reference::{classify, edge_band, PixelClass, ReferenceScene};
use glam::Vec3;
use serde::Serialize;
use umbra::gpu::GpuError;
use umbra::math::Aabb;
use umbra::plan::{SceneOptions, ShadowHold, ShadowMethod, View};
use umbra::render::Renderer;
use umbra::scene::anim::{add_mover, Playing};
use umbra::scene::built::shapes::{colored, cuboid};
use umbra::scene::{Light, Scene};

/// One probe flown with one method.
#[derive(Clone, Debug, Serialize)]
pub struct MotionSeries {
    /// "moving caster" or "sun arc".
    pub probe: String,
    /// What moves: the animation's name, or "added box".
    pub mover: String,
    /// "defaults" (maps fitted afresh per frame), "defaults, held" (the viewer), "exact" or
    /// "hybrid".
    pub method: String,
    /// Per consecutive pair: still points whose exact visibility is the same in both frames.
    pub points: Vec<usize>,
    /// Per pair: of those, points whose GPU classification flipped.
    pub flipped: Vec<usize>,
    /// Mean over pairs of the flipped fraction.
    pub mean_fraction: f64,
    /// Largest flipped fraction of one pair.
    pub max_fraction: f64,
    /// Per pair: the still points away from edges (beyond `EDGE_PIXELS` of an exact shadow
    /// boundary in both frames), and of those, the ones that flipped.
    pub interior: Vec<(usize, usize)>,
    /// Mean over pairs of the flipped fraction away from edges.
    pub mean_interior_fraction: f64,
}

/// How a probe is flown: maps fitted afresh each frame, maps held across frames, exact shadows,
/// and hybrid shadows (the map's verdict where it proves one, traced elsewhere).
pub const METHODS: [(&str, bool, ShadowMethod); 4] = [
    ("defaults", false, ShadowMethod::Map),
    ("defaults, held", true, ShadowMethod::Map),
    ("exact", false, ShadowMethod::Exact),
    ("hybrid", false, ShadowMethod::Hybrid),
];

/// Frames of each probe: 2 s at 60 frames per second (`quick`: its first half second).
pub fn frames(quick: bool) -> usize {
    if quick {
        30
    } else {
        120
    }
}

/// The moving-caster scene and the animation that moves it: `scene` itself when it has
/// animations (`animation`, else its first), else `scene` with a box a tenth of its radius
/// across moving along [`box_path`] ("move", then the scene's last animation).
pub fn mover_scene(scene: &Scene, sun: Vec3, animation: Option<usize>) -> (Scene, usize, String) {
    if let Some(r) = scene.rig.as_deref().filter(|r| !r.animations.is_empty()) {
        let i = animation.unwrap_or(0).min(r.animations.len() - 1);
        return (scene.clone(), i, r.animations[i].name.clone());
    }
    let mut s = scene.clone();
    let b = scene.bounds();
    let half = Vec3::splat(0.05 * b.diagonal().max(1e-6));
    add_mover(
        &mut s,
        "probe mover",
        cuboid(half),
        colored(Vec3::new(0.3, 0.5, 0.8), 0.8),
        &box_path(&b, sun, 2.0),
    );
    let last = s.rig.as_deref().map_or(0, |r| r.animations.len() - 1);
    (s, last, "added box".into())
}

/// The box's keys over `duration` seconds: from beyond one side of `b` low over the ground,
/// across its centre (where cascade splits fall), up towards the sun (`sun`: the direction its
/// light travels) to 1.5 radii, then out past the bounds on the far side.
pub fn box_path(b: &Aabb, sun: Vec3, duration: f32) -> Vec<(f32, Vec3)> {
    let c = b.center();
    let r = (b.diagonal() * 0.5).max(1e-6);
    let low = b.min.y + 0.15 * r;
    let across = Vec3::new(1.0, 0.0, 0.3).normalize();
    let points = [
        c - across * r * 1.2 + Vec3::Y * (low - c.y),
        Vec3::new(c.x, low, c.z),
        c - sun.normalize_or(Vec3::NEG_Y) * 1.5 * r,
        c + across * r * 1.6 + Vec3::Y * (low + 0.2 * r - c.y),
    ];
    points
        .iter()
        .enumerate()
        .map(|(i, p)| (duration * i as f32 / 3.0, *p))
        .collect()
}

/// The sun of frame `i` of `n` on the time-of-day arc: elevation 10° → 70°, azimuth 60° → 120°.
pub fn sun_arc(i: usize, n: usize) -> Vec3 {
    let t = i as f32 / (n.max(2) - 1) as f32;
    Light::sun_direction(
        (10.0 + 60.0 * t).to_radians(),
        (60.0 + 60.0 * t).to_radians(),
    )
}

/// One frame of a probe: the GPU's shadow view (with depth), the exact visibility and its edge
/// band.
struct Frame {
    lit: Vec<Option<bool>>,
    depth: Vec<f32>,
    exact: Vec<Option<bool>>,
    edge: Vec<bool>,
}

/// Still points and of those the flipped ones.
type Counts = (usize, usize);

/// Flicker between consecutive frames: (points, flipped), and the same away from edges.
fn flicker(a: &Frame, b: &Frame) -> (Counts, Counts) {
    let (mut n, mut f) = (0, 0);
    let (mut ni, mut fi) = (0, 0);
    for i in 0..a.depth.len() {
        let (da, db) = (a.depth[i], b.depth[i]);
        // The same still surface: same depth (to 1e-6 relative) in both frames.
        if da <= 0.0 || (da - db).abs() > 1e-6 * da.max(db) {
            continue;
        }
        let (Some(ea), Some(eb)) = (a.exact[i], b.exact[i]) else {
            continue;
        };
        if ea != eb {
            continue;
        }
        let (Some(ga), Some(gb)) = (a.lit[i], b.lit[i]) else {
            continue;
        };
        n += 1;
        f += (ga != gb) as usize;
        if !a.edge[i] && !b.edge[i] {
            ni += 1;
            fi += (ga != gb) as usize;
        }
    }
    ((n, f), (ni, fi))
}

fn render(
    renderer: &mut Renderer,
    scene: &Scene,
    view: &View,
    size: (u32, u32),
) -> Result<(Frame, ShadowHold), GpuError> {
    let f = shadow_frame(renderer, view, size)?;
    let exact = ReferenceScene::new(scene).render(&f.plan, size.0, size.1, f.plan.ambient);
    let depth = f.depth.clone().unwrap_or_default();
    // Judged where the GPU and the reference see the same surface (`classify`'s rule).
    let judged = classify(&f.image, &depth, &f.plan, &exact);
    let lit = f
        .image
        .pixels()
        .zip(&judged.class)
        .map(|(p, c)| (*c != PixelClass::Unjudged).then_some(p[0] >= 128))
        .collect();
    Ok((
        Frame {
            lit,
            depth,
            edge: edge_band(&exact.visibility, size.0, size.1),
            exact: exact.visibility,
        },
        ShadowHold::from_plan(&f.plan),
    ))
}

/// Both probes, each flown with every one of `METHODS`; `progress` is called once per frame
/// rendered.
pub fn motion(
    ctx: &std::sync::Arc<umbra::gpu::Context>,
    scene: &Scene,
    view: &View,
    options: &SceneOptions,
    opts: &super::StabilityOptions,
    progress: &mut dyn FnMut(),
) -> Result<Vec<MotionSeries>, GpuError> {
    let (size, quick) = (opts.size, opts.quick);
    let n = frames(quick);
    let sun = umbra::plan::effective_lights(&scene.lights, view)
        .iter()
        .find(|l| l.kind == umbra::scene::LightKind::Directional)
        .map_or(Vec3::NEG_Y, |l| l.direction);
    let (mut moving, anim, mover) = mover_scene(scene, sun, opts.animation);
    let playing = Playing::One(anim);
    let duration = moving.rig.as_deref().map_or(0.0, |r| r.duration(&playing));
    let mut out = Vec::new();
    let mut renderer = Renderer::with_options(ctx, &moving, options)?;
    for (name, held, method) in METHODS {
        let mut frames = Vec::new();
        let mut hold = None;
        for i in 0..n {
            // The first half second of a quick run, the whole animation otherwise (at 60 fps
            // for the added box's 2 s).
            let t = (i as f32 / 60.0).min(duration);
            moving.pose_at(&playing, t);
            renderer.set_pose(&moving)?;
            let mut v = view.clone();
            v.shadow.method = method;
            v.shadow_hold = if held { hold.clone() } else { None };
            let (f, h) = render(&mut renderer, &moving, &v, size)?;
            hold = Some(h);
            frames.push(f);
            progress();
        }
        out.push(series("moving caster", &mover, name, &frames));
    }
    drop(renderer);
    let mut renderer = Renderer::with_options(ctx, scene, options)?;
    for (name, held, method) in METHODS {
        let mut frames = Vec::new();
        let mut hold = None;
        for i in 0..n {
            let mut v = view.clone();
            v.sun_direction = Some(sun_arc(i, frames_full(quick, n)));
            v.shadow.method = method;
            v.shadow_hold = if held { hold.clone() } else { None };
            let (f, h) = render(&mut renderer, scene, &v, size)?;
            hold = Some(h);
            frames.push(f);
            progress();
        }
        out.push(series("sun arc", "sun", name, &frames));
    }
    Ok(out)
}

/// The arc is laid over the full run's frames, so a quick run flies its first part at the same
/// speed.
fn frames_full(quick: bool, n: usize) -> usize {
    if quick {
        frames(false)
    } else {
        n
    }
}

fn series(probe: &str, mover: &str, method: &str, frames: &[Frame]) -> MotionSeries {
    let (all, interior): (Vec<Counts>, Vec<Counts>) =
        frames.windows(2).map(|w| flicker(&w[0], &w[1])).unzip();
    let (points, flipped): (Vec<usize>, Vec<usize>) = all.into_iter().unzip();
    let mean = |fr: &[f64]| fr.iter().sum::<f64>() / fr.len().max(1) as f64;
    let fr: Vec<f64> = points
        .iter()
        .zip(&flipped)
        .map(|(&n, &f)| fraction(f, n))
        .collect();
    let fri: Vec<f64> = interior.iter().map(|&(n, f)| fraction(f, n)).collect();
    MotionSeries {
        probe: probe.into(),
        mover: mover.into(),
        method: method.into(),
        mean_fraction: mean(&fr),
        max_fraction: fr.iter().copied().fold(0.0, f64::max),
        points,
        flipped,
        mean_interior_fraction: mean(&fri),
        interior,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(lit: &[Option<bool>], exact: &[Option<bool>], depth: &[f32]) -> Frame {
        Frame {
            lit: lit.to_vec(),
            depth: depth.to_vec(),
            exact: exact.to_vec(),
            edge: vec![false; lit.len()],
        }
    }

    #[test]
    fn flicker_counts_flips_of_still_points_whose_exact_visibility_holds() {
        let a = frame(
            &[Some(true), Some(true), Some(false), Some(true), None],
            &[Some(true), Some(true), Some(false), Some(true), None],
            &[0.5, 0.5, 0.5, 0.5, 0.0],
        );
        // Point 0 flips (flicker); point 1 stays; point 2's exact visibility changes too (a
        // real shadow edge moving: not flicker); point 3's surface moved (another depth).
        let b = frame(
            &[Some(false), Some(true), Some(true), Some(false), None],
            &[Some(true), Some(true), Some(true), Some(true), None],
            &[0.5, 0.5, 0.5, 0.6, 0.0],
        );
        assert_eq!(flicker(&a, &b), ((2, 1), (2, 1)));
        // Point 0 within the edge band of one frame: flicker, but not away from edges.
        let mut b = b;
        b.edge[0] = true;
        assert_eq!(flicker(&a, &b), ((2, 1), (1, 0)));
    }

    #[test]
    fn the_box_path_crosses_the_centre_rises_and_leaves() {
        let b = Aabb::from_points([Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 1.0, 1.0)]);
        let keys = box_path(&b, Vec3::new(0.0, -1.0, 0.0), 2.0);
        assert_eq!(keys.len(), 4);
        assert_eq!(keys[3].0, 2.0);
        assert!(
            keys[2].1.y > b.max.y,
            "rises towards the sun: {}",
            keys[2].1
        );
        assert!(
            !b.contains(keys[0].1, 0.0) && !b.contains(keys[3].1, 0.0),
            "starts and ends outside"
        );
        let elevation = |d: Vec3| (-d.y).asin().to_degrees();
        assert!((elevation(sun_arc(0, 120)) - 10.0).abs() < 1e-3);
        assert!((elevation(sun_arc(119, 120)) - 70.0).abs() < 1e-3);
    }
}
