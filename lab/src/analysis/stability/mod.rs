//! Stability where shadow methods fail (feature `sweep`): probes that stress a scene where shadow
//! mapping is known to break, each measured against the exact ray-cast reference and returned as
//! serialisable rows, then judged against stated thresholds ([`report`]).
//!
//! - [`light`]: sun elevation from 0.5° to 90° × azimuths: acne (false shadow away from exact
//!   edges) on planar and curved receivers, leaks; a bias sweep for the acne / peter-panning
//!   trade-off; and, on the built-in scene, the contact gap at a thin wall's base in texels.
//! - [`shimmer`]: a cubic Bézier flythrough; the fraction of fixed world points whose shadow
//!   classification flips between consecutive frames, per shadow method.
//! - [`motion`]: a still camera over a moving caster (the scene's animation, or an added box
//!   crossing the cascades, rising to the light and leaving the bounds) and under a moving sun;
//!   the fraction of still points whose classification flips while their exact visibility holds.
//! - [`precision`]: the scene translated to 10⁰…10⁶ units and scaled 10⁻³…10⁴.
//! - [`degenerate`]: degenerate lights, cameras and scenes: each must render with no validation
//!   message, finite depth and its documented result.

pub mod degenerate;
pub mod light;
pub mod motion;
pub mod precision;
pub mod report;
pub mod shimmer;

use crate::reference::{classify, Classified, PixelClass, ReferenceFrame, ReferenceScene};
use serde::Serialize;
use umbra::gpu::GpuError;
use umbra::plan::{View, ViewMode};
use umbra::render::{RenderedFrame, Renderer};

/// Schema name of `stability.json`.
pub const SCHEMA: &str = "umbra-stability/1";

/// Pixel counts of one frame classified against the exact reference. Acne is false shadow that
/// does not belong to a misplaced shadow edge or a silhouette: a false-shadow region (8-connected)
/// that touches no exactly shadowed pixel, no edge band (2 pixels around exact edges,
/// `reference::metrics::EDGE_PIXELS`), no silhouette (where one pixel sample of a surface seen
/// edge-on decides), not the frame's border band of the same width (an exact edge may lie just
/// outside the frame, where no band is drawn), and has no caster within the shadow lookup's reach
/// across the light ([`near_casters`]: the shadow of a caster the map resolves only to its texels,
/// drawn too wide, whose exact shadow may be hidden behind the caster or thinner than a pixel). A shadow drawn too wide, which at grazing sun reaches far past any pixel
/// band, is false shadow at the edge, not acne. Planar and curved split the judged
/// pixels by the receiver (curved: interpolated normal more than 1° off the face normal).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Counts {
    /// Pixels where GPU and reference see the same surface.
    pub judged: usize,
    /// Judged pixels on planar receivers.
    pub planar: usize,
    /// Judged pixels on curved receivers.
    pub curved: usize,
    /// Acne on planar receivers.
    pub acne_planar: usize,
    /// Acne on curved receivers.
    pub acne_curved: usize,
    /// False shadow attached to an exact shadow, its edge band or a silhouette.
    pub false_shadow_edge: usize,
    /// False light away from edges (leaks).
    pub false_light_interior: usize,
    /// False light within the edge bands (peter-panning shows here first).
    pub false_light_edge: usize,
    /// Judged pixels on receivers within [`EDGE_ON_DEGREES`] of edge-on to the light.
    pub edge_on: usize,
    /// Of those, acne and false light away from edges (counted in the totals above too).
    pub edge_on_interior: usize,
}

/// Receivers turned less than this many degrees towards the light (|n·l| < sin 5°) are
/// *edge-on*: a map texel spreads over more than 11 texel lengths of them (projective aliasing),
/// so their shadow comes from a texel or two however fine the map, and their lighting is under
/// 9 % of full. The degenerate cases judge them apart (reported, not bounded); the same 5° is the
/// issue's own limit for curved receivers.
pub const EDGE_ON_DEGREES: f32 = 5.0;

impl Counts {
    /// Counts the classes of `c` against the exact frame it was classified with.
    pub fn of(c: &Classified, exact: &ReferenceFrame) -> Self {
        Self::with_casters(c, exact, &[])
    }

    /// As [`Counts::of`], where `near_caster[i]` says that false-shadow pixel `i` has a caster
    /// within the shadow lookup's reach across the light (see [`near_casters`]): that pixel is
    /// the caster's shadow drawn too wide, not acne (it attaches no neighbour: acne spreads over
    /// receivers near casters too).
    pub fn with_casters(c: &Classified, exact: &ReferenceFrame, near_caster: &[bool]) -> Self {
        let attached = attached_false_shadow(c, exact);
        let near = |i: usize| near_caster.get(i).copied().unwrap_or(false);
        let mut k = Counts::default();
        for (i, class) in c.class.iter().enumerate() {
            if *class == PixelClass::Unjudged {
                continue;
            }
            k.judged += 1;
            let bent = exact.curved.get(i).copied().unwrap_or(false);
            if bent {
                k.curved += 1;
            } else {
                k.planar += 1;
            }
            let edge_on = exact
                .incidence
                .get(i)
                .is_some_and(|c| c.abs() < EDGE_ON_DEGREES.to_radians().sin());
            if edge_on {
                k.edge_on += 1;
                let interior = match *class {
                    PixelClass::FalseShadow => !attached[i] && !near(i),
                    PixelClass::FalseLight => !c.edge[i],
                    _ => false,
                };
                k.edge_on_interior += interior as usize;
            }
            match *class {
                PixelClass::FalseShadow if attached[i] || near(i) => k.false_shadow_edge += 1,
                PixelClass::FalseShadow if bent => k.acne_curved += 1,
                PixelClass::FalseShadow => k.acne_planar += 1,
                PixelClass::FalseLight if c.edge[i] => k.false_light_edge += 1,
                PixelClass::FalseLight => k.false_light_interior += 1,
                _ => {}
            }
        }
        k
    }

    /// All misclassified pixels.
    pub fn misclassified(&self) -> usize {
        self.acne_planar
            + self.acne_curved
            + self.false_shadow_edge
            + self.false_light_interior
            + self.false_light_edge
    }

    /// Misclassified fraction of the judged pixels.
    pub fn misclassified_fraction(&self) -> f64 {
        fraction(self.misclassified(), self.judged)
    }

    /// Acne fraction of the judged pixels (planar and curved).
    pub fn acne_fraction(&self) -> f64 {
        fraction(self.acne_planar + self.acne_curved, self.judged)
    }

    /// False-light fraction of the judged pixels (edges and interior).
    pub fn false_light_fraction(&self) -> f64 {
        fraction(
            self.false_light_interior + self.false_light_edge,
            self.judged,
        )
    }
}

/// Relative jump in distance between neighbouring pixels that marks a silhouette.
const SILHOUETTE_JUMP: f32 = 0.05;

/// False-shadow pixels 8-connected (through false shadow) to an edge band, to a pixel the exact
/// answer shadows, or to a silhouette (a neighbour not judged, or more than 5 % nearer or
/// farther).
fn attached_false_shadow(c: &Classified, exact: &ReferenceFrame) -> Vec<bool> {
    let (w, h) = (c.width as i64, c.height as i64);
    let fs = |i: usize| c.class[i] == PixelClass::FalseShadow;
    let mut attached = vec![false; c.class.len()];
    let mut stack: Vec<usize> = Vec::new();
    let neighbours = |i: usize| {
        let (x, y) = (i as i64 % w, i as i64 / w);
        (-1..=1i64)
            .flat_map(move |dy| (-1..=1i64).map(move |dx| (x + dx, y + dy)))
            .filter(move |&(nx, ny)| nx >= 0 && ny >= 0 && nx < w && ny < h)
            .map(move |(nx, ny)| (ny * w + nx) as usize)
    };
    // Within the edge band's width of the frame's border, an exact edge may lie just outside
    // the frame, where no band was drawn: attachment there cannot be ruled out.
    let band = crate::reference::metrics::EDGE_PIXELS as i64;
    let at_border = |i: usize| {
        let (x, y) = (i as i64 % w, i as i64 / w);
        x < band || y < band || x >= w - band || y >= h - band
    };
    let seeds: Vec<usize> = (0..c.class.len())
        .filter(|&i| {
            let d = exact.distance[i];
            fs(i)
                && (c.edge[i]
                    || at_border(i)
                    || neighbours(i).any(|j| {
                        exact.visibility[j] == Some(false)
                            || c.class[j] == PixelClass::Unjudged
                            || (exact.distance[j] - d).abs() > SILHOUETTE_JUMP * d
                    }))
        })
        .collect();
    for i in seeds {
        attached[i] = true;
        stack.push(i);
    }
    while let Some(i) = stack.pop() {
        for j in neighbours(i) {
            if fs(j) && !attached[j] {
                attached[j] = true;
                stack.push(j);
            }
        }
    }
    attached
}

/// a / b, 0 when b is 0.
pub fn fraction(a: usize, b: usize) -> f64 {
    if b == 0 {
        0.0
    } else {
        a as f64 / b as f64
    }
}

/// Renders `view`'s shadow visibility (with depth) at `w`×`h`.
pub fn shadow_frame(
    renderer: &mut Renderer,
    view: &View,
    (w, h): (u32, u32),
) -> Result<RenderedFrame, GpuError> {
    let mut v = view.clone();
    v.mode = ViewMode::Shadow;
    renderer.set_read_depth(true);
    let f = renderer.render(&v, w, h);
    renderer.set_read_depth(false);
    f
}

/// One frame classified against the exact reference: the counts, the GPU frame and the exact
/// frame (which depends on the camera and lights only, so a caller may keep it for other shadow
/// settings of the same view: pass it back as `exact`).
pub fn classify_view(
    renderer: &mut Renderer,
    reference: &ReferenceScene,
    view: &View,
    size: (u32, u32),
    exact: &mut Option<ReferenceFrame>,
) -> Result<(Counts, RenderedFrame), GpuError> {
    let f = shadow_frame(renderer, view, size)?;
    let frame =
        exact.get_or_insert_with(|| reference.render(&f.plan, size.0, size.1, f.plan.ambient));
    let c = classify(&f.image, f.depth.as_deref().unwrap_or(&[]), &f.plan, frame);
    let near = near_casters(reference, view, &f, &c, size);
    Ok((Counts::with_casters(&c, frame, &near), f))
}

/// Shadow texels around a lookup that can decide it: the filter's reach, the normal offset (which
/// moves the lookup across the light by up to that many texels) and one for rasterising casters
/// at texel centres.
pub fn lookup_reach_texels(s: &umbra::plan::ShadowSettings, soft: bool) -> f32 {
    umbra::plan::lookup_reach(s.pcf, soft) as f32 + s.normal_offset.max(0.0) + 1.0
}

/// Per pixel of `c`: a false shadow with a caster of the shadowed light within
/// [`lookup_reach_texels`] of its surface point across the light
/// ([`ReferenceScene::caster_within`]), the texel being that of the finest shadow view holding
/// the point. Only false-shadow pixels are tested; the rest are false.
pub fn near_casters(
    reference: &ReferenceScene,
    view: &View,
    f: &RenderedFrame,
    c: &Classified,
    (w, h): (u32, u32),
) -> Vec<bool> {
    let mut near = vec![false; c.class.len()];
    let Some(light) = f.plan.shadow_light else {
        return near;
    };
    let views = f.plan.light_views(light);
    let reach = lookup_reach_texels(&view.shadow, f.plan.soft);
    let idx: Vec<usize> = (0..c.class.len())
        .filter(|&i| c.class[i] == PixelClass::FalseShadow)
        .collect();
    let pixels: Vec<(f32, f32)> = idx
        .iter()
        .map(|&i| ((i as u32 % w) as f32 + 0.5, (i as u32 / w) as f32 + 0.5))
        .collect();
    let probes = reference.probe(&f.plan, &pixels, w, h);
    let point_light = f
        .plan
        .lights
        .get(light)
        .filter(|l| l.kind != umbra::scene::LightKind::Directional)
        .map(|l| l.position);
    for (&i, probe) in idx.iter().zip(probes) {
        let Some(p) = probe else { continue };
        let holds = |v: &&umbra::plan::ShadowView| {
            let q = umbra::math::shadow_fit::project(&v.light_clip_from_world, p.position);
            q.x.abs() <= 1.0 && q.y.abs() <= 1.0 && (0.0..=1.0).contains(&q.z)
        };
        let Some(v) = views.iter().find(holds).or(views.last()) else {
            continue;
        };
        let texel = match point_light {
            Some(at) => v.texel_world * at.distance(p.position),
            None => v.texel_world,
        };
        near[i] = reference.caster_within(
            &f.plan,
            light,
            (p.position, p.offset),
            p.normal,
            reach * texel,
        );
    }
    near
}

/// `view` of `scene` classified on a renderer and a reference of its own, for probes that change
/// the scene itself; the renderer is returned for further frames.
pub fn classify_scene(
    ctx: &std::sync::Arc<umbra::gpu::Context>,
    scene: &umbra::scene::Scene,
    options: &umbra::plan::SceneOptions,
    view: &View,
    size: (u32, u32),
) -> Result<(Counts, RenderedFrame, Renderer), GpuError> {
    let mut renderer = Renderer::with_options(ctx, scene, options)?;
    let reference = ReferenceScene::new(scene);
    let (c, f) = classify_view(&mut renderer, &reference, view, size, &mut None)?;
    Ok((c, f, renderer))
}

/// The world size of one texel of the shown light's finest shadow view (0 without one).
pub fn finest_texel(f: &RenderedFrame) -> f64 {
    f.plan
        .primary_views()
        .iter()
        .map(|v| v.texel_world as f64)
        .reduce(f64::min)
        .unwrap_or(0.0)
}

/// What the suite measures and how finely.
#[derive(Clone, Debug)]
pub struct StabilityOptions {
    /// Frame size for every probe.
    pub size: (u32, u32),
    /// Fewer angles, frames and cases (for tests and a first look).
    pub quick: bool,
    /// The animation the motion probe's moving caster plays (None: the scene's first).
    pub animation: Option<usize>,
}

impl Default for StabilityOptions {
    fn default() -> Self {
        Self {
            size: (640, 360),
            quick: false,
            animation: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 12×8 frame on one flat surface: exact shadow in columns 0–3, everything judged.
    fn frame(gpu_shadow: &[(u32, u32)]) -> (Classified, ReferenceFrame) {
        let (w, h) = (12u32, 8u32);
        let n = (w * h) as usize;
        let visibility: Vec<Option<bool>> = (0..n).map(|i| Some(i as u32 % w >= 4)).collect();
        let exact = ReferenceFrame {
            width: w,
            height: h,
            coverage: visibility
                .iter()
                .map(|v| v.map(|v| v as u8 as f32))
                .collect(),
            visibility,
            distance: vec![10.0; n],
            image: image::RgbaImage::new(w, h),
            curved: vec![false; n],
            incidence: vec![1.0; n],
            coincident: vec![false; n],
        };
        let mut class = vec![PixelClass::Correct; n];
        for &(x, y) in gpu_shadow {
            class[(y * w + x) as usize] = PixelClass::FalseShadow;
        }
        // Edge band: columns 2–5 (2 pixels around the boundary between columns 3 and 4).
        let edge = (0..n).map(|i| (2..=5).contains(&(i as u32 % w))).collect();
        (
            Classified {
                width: w,
                height: h,
                class,
                edge,
                coverage_mismatch: 0,
                coincident: 0,
            },
            exact,
        )
    }

    #[test]
    fn isolated_false_shadow_is_acne_and_a_widened_shadow_is_not() {
        // A speck in the lit middle: acne.
        let (c, e) = frame(&[(8, 4), (9, 4)]);
        let k = Counts::of(&c, &e);
        assert_eq!((k.acne_planar, k.false_shadow_edge), (2, 0));
        // The shadow drawn 5 columns too wide (reaching past the edge band): attached, not acne.
        let wide: Vec<(u32, u32)> = (0..8).flat_map(|y| (4..9).map(move |x| (x, y))).collect();
        let (c, e) = frame(&wide);
        let k = Counts::of(&c, &e);
        assert_eq!((k.acne_planar, k.false_shadow_edge), (0, 40));
        assert_eq!(k.judged, 96);
    }

    #[test]
    fn false_shadow_at_the_frame_border_is_not_acne() {
        // The same speck on the bottom row: an exact edge may lie just below the frame.
        let (c, e) = frame(&[(8, 7), (9, 7), (8, 4)]);
        let k = Counts::of(&c, &e);
        assert_eq!((k.acne_planar, k.false_shadow_edge), (1, 2));
    }

    #[test]
    fn false_shadow_beside_a_caster_is_not_acne() {
        // Two specks in the lit middle; the reference finds a caster within the lookup's reach
        // of one of them (its exact shadow hidden or thinner than a pixel): only the other is
        // acne.
        let (c, e) = frame(&[(8, 4), (7, 2)]);
        let mut near = vec![false; 96];
        near[4 * 12 + 8] = true;
        let k = Counts::with_casters(&c, &e, &near);
        assert_eq!((k.acne_planar, k.false_shadow_edge), (1, 1));
    }

    #[test]
    fn edge_on_receivers_are_counted_apart() {
        // Columns 8–11 turned 3° towards the light (edge-on), one speck of acne there and one on
        // a receiver facing the light.
        let (mut c, mut e) = frame(&[(9, 4), (6, 3)]);
        for (i, inc) in e.incidence.iter_mut().enumerate() {
            if i % 12 >= 8 {
                *inc = 3f32.to_radians().sin();
            }
        }
        c.class[4 * 12 + 10] = PixelClass::FalseLight;
        let k = Counts::of(&c, &e);
        assert_eq!((k.edge_on, k.edge_on_interior), (32, 2));
        assert_eq!((k.acne_planar, k.false_light_interior), (2, 1));
    }
}
