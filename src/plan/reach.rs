//! Where a frame's single shadow view can shadow anything (`ShadowReach`): the region the
//! camera pass draws with the shadowed shader when small receivers are drawn unshadowed beyond
//! it (`render::passes::receivers`). Pure geometry: half-spaces of the view's casters'
//! rectangle, grown by the lookup's offset.

use crate::math::Aabb;
use glam::{Mat4, Vec3, Vec4};

/// Texels added to the normal offset and constant bias when growing the reach (rounding).
const SLACK_TEXELS: f32 = 1.0;

/// The world region where a frame's single shadow view can return less than 1: the points whose
/// lookup point (the point moved by its normal offset and bias) projects inside the casters'
/// rectangle, in front of a spot light.
#[derive(Clone, Debug)]
pub struct ShadowReach {
    /// Half-spaces `n·p + d ≥ 0` with unit `n`, before growing by the lookup offset.
    planes: Vec<Vec4>,
    /// A perspective view's apex (the spot light), where its side planes meet.
    apex: Option<Vec3>,
    /// How far a lookup point can lie from its point, in texels of the view.
    offset_texels: f32,
    /// World size of a texel (directional), or per unit distance from the light (spot).
    texel_world: f32,
}

impl ShadowReach {
    /// The reach of a view `light_clip_from_world` whose `size`-texel square has its casters'
    /// lookup rectangle `lookup` (texels `(x0, y0, x1, y1)`, rows down; empty when `x0 > x1`),
    /// lookups moved up to `offset_texels` texels (normal offset + constant bias) of
    /// `texel_world` each; `apex` is the spot light's position (None for a directional light).
    pub fn new(
        light_clip_from_world: &Mat4,
        lookup: Vec4,
        size: f32,
        offset_texels: f32,
        texel_world: f32,
        apex: Option<Vec3>,
    ) -> Self {
        let never = Vec4::new(0.0, 0.0, 0.0, -1.0);
        let with = |planes| Self {
            planes,
            apex,
            offset_texels: offset_texels.max(0.0) + SLACK_TEXELS,
            texel_world,
        };
        if !(lookup.x <= lookup.z && lookup.y <= lookup.w) {
            // An empty casters' rectangle: every lookup is lit.
            return with(vec![never]);
        }
        let m = light_clip_from_world;
        let (rx, ry, rw) = (m.row(0), m.row(1), m.row(3));
        // Texel u = (ndc.x / 2 + 1/2)·size, v = (1/2 − ndc.y / 2)·size; with w > 0:
        // u ≥ x0 ⇔ clip.x − a·clip.w ≥ 0 (a = 2·x0/size − 1), and so on.
        let ndc_x = |t: f32| 2.0 * t / size - 1.0;
        let ndc_y = |t: f32| 1.0 - 2.0 * t / size;
        let mut raw = vec![
            rx - ndc_x(lookup.x) * rw,
            ndc_x(lookup.z) * rw - rx,
            ndc_y(lookup.y) * rw - ry,
            ry - ndc_y(lookup.w) * rw,
        ];
        if apex.is_some() {
            // A lookup at or behind the light's plane is lit.
            raw.push(rw);
        }
        // Unit normals; a constant row (an orthographic w) holds everywhere or nowhere.
        let planes = raw
            .into_iter()
            .filter_map(|p| {
                let n = p.truncate().length();
                if n > 1e-12 {
                    Some(p / n)
                } else {
                    (p.w < 0.0).then_some(never)
                }
            })
            .collect();
        with(planes)
    }

    /// The corners of the part of `bounds` whose points may have a lookup that reads a caster
    /// (a superset: the planes grown by the largest lookup offset over `bounds`); None when
    /// no point of `bounds` can.
    pub fn clip(&self, bounds: &Aabb) -> Option<Vec<Vec3>> {
        let scale = match self.apex {
            Some(a) => bounds
                .corners()
                .iter()
                .map(|c| c.distance(a))
                .fold(0.0, f32::max),
            None => 1.0,
        };
        let grow = self.offset_texels * self.texel_world * scale;
        let planes: Vec<Vec4> = self.planes.iter().map(|p| *p + Vec4::W * grow).collect();
        let mut corners = Vec::new();
        for face in box_faces(bounds) {
            let mut poly = face.to_vec();
            for p in &planes {
                poly = clip_polygon(&poly, *p);
                if poly.is_empty() {
                    break;
                }
            }
            corners.extend(poly);
        }
        // Vertices on no face of the box: only a spot light's apex, where its planes meet.
        if let Some(a) = self.apex.filter(|a| bounds.contains(*a, 0.0)) {
            corners.push(a);
        }
        (!corners.is_empty()).then_some(corners)
    }
}

/// The six faces of `b` as quads.
fn box_faces(b: &Aabb) -> [[Vec3; 4]; 6] {
    let c = b.corners();
    // corners(): bit 0 → x max, bit 1 → y max, bit 2 → z max.
    let quad = |i: [usize; 4]| [c[i[0]], c[i[1]], c[i[2]], c[i[3]]];
    [
        quad([0, 2, 6, 4]),
        quad([1, 3, 7, 5]),
        quad([0, 1, 5, 4]),
        quad([2, 3, 7, 6]),
        quad([0, 1, 3, 2]),
        quad([4, 5, 7, 6]),
    ]
}

/// The part of convex polygon `poly` where `plane·(p, 1) ≥ 0` (Sutherland–Hodgman).
fn clip_polygon(poly: &[Vec3], plane: Vec4) -> Vec<Vec3> {
    let f = |p: Vec3| plane.truncate().dot(p) + plane.w;
    let mut out = Vec::with_capacity(poly.len() + 1);
    for (i, &a) in poly.iter().enumerate() {
        let b = poly[(i + 1) % poly.len()];
        let (fa, fb) = (f(a), f(b));
        if fa >= 0.0 {
            out.push(a);
        }
        if (fa >= 0.0) != (fb >= 0.0) {
            out.push(a + (b - a) * (fa / (fa - fb)));
        }
    }
    out
}
