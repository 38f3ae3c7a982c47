//! Cutout cards cut to their texture's alpha, for the shadow pass.
//!
//! Foliage is drawn as cards: quads (or lone triangles) whose base-colour texture draws a leaf
//! cluster in alpha, most of the card clear. The shadow pass alpha-tests every texel of every
//! card, in every cascade, and its discarding fragment shader keeps the rasteriser from
//! rejecting any of them early. Here each lone card is cut to where its alpha can reach the
//! shadow cutoff: the bounding rectangle, in texture space, of the texels that can pass, each
//! grown by the reach of bilinear filtering at mip 0 (what the shadow pass samples). The clear
//! rest is never rasterised; a card none of whose texels can pass is left out.
//!
//! A rectangle, not a tighter polygon: on llvmpipe every triangle a card gains costs more than
//! the fragments it saves. On the foliage scene's leaf cards an 8-direction polygon keeps 0.56 of
//! each card in 8–10 triangles and its shadow pass took 29 ms; the rectangle keeps 0.68 in 2 and
//! took 24 ms; whole cards 32–34 ms.
//!
//! Only patches that share no edge with the rest of the mesh are cut (a lone triangle, or two
//! triangles sharing one edge that make one flat, convex quad with one affine texture mapping
//! and one vertex alpha), so a cut cannot open a crack against a neighbour; every other triangle
//! is kept as it is. The camera pass keeps the whole cards: it samples coarser mips, whose
//! alpha reaches further.

use crate::scene::AlphaMode;
use crate::scene::{Material, Primitive, Sampler, Texture, UvTransform, BLEND_SHADOW_CUTOFF};
use glam::{Vec2, Vec3, Vec4};
use std::collections::HashMap;

/// Extra reach of a texel's bilinear footprint, in texels, for the device's fixed-point filter
/// weights.
const REACH_MARGIN: f32 = 1.0 / 64.0;

/// Largest lattice (texels) one patch's texture footprint may span before it is kept whole (a
/// card over a whole 4096² texture, with the reach around it).
const MAX_FOOTPRINT: i64 = 4104 * 4104;

/// Where a primitive's alpha test reads, and which texels can pass it.
pub struct AlphaCut<'a> {
    texture: &'a Texture,
    sampler: Sampler,
    transform: UvTransform,
    tex_coord: u32,
    /// Texels whose alpha byte is at least this can pass (256: none can).
    min_alpha: u16,
}

impl<'a> AlphaCut<'a> {
    /// The shadow pass's alpha test of `m` on primitive `p` (alpha = vertex alpha × base-colour
    /// factor × texel alpha ≥ the cutoff: the material's for MASK, `BLEND_SHADOW_CUTOFF` for
    /// BLEND), or None where there is nothing to cut: an opaque material, no base-colour
    /// texture, or every texel able to pass.
    pub fn new(m: &Material, p: &Primitive, textures: &'a [Texture]) -> Option<Self> {
        let cutoff = match m.alpha_mode {
            AlphaMode::Mask(c) => c.max(1e-6),
            AlphaMode::Blend => BLEND_SHADOW_CUTOFF,
            AlphaMode::Opaque => return None,
        };
        let tex = m.base_color_texture?;
        let texture = textures.get(tex.texture)?;
        let vertex_alpha = p.colors.iter().map(|c| c.w).fold(1.0f32, f32::max);
        let factor = (m.base_color.w * vertex_alpha).max(0.0);
        // A texel passes where factor · a / 255 ≥ cutoff; a half step of slack for the
        // device's rounding.
        let need = 255.0 * (cutoff - 1.0 / 512.0) / factor;
        let min_alpha = if need.is_nan() || need > 255.0 {
            256
        } else if need <= 0.0 {
            return None;
        } else {
            need.ceil() as u16
        };
        Some(Self {
            texture,
            sampler: tex.sampler,
            transform: tex.transform,
            tex_coord: tex.tex_coord,
            min_alpha,
        })
    }

    /// The coordinates the alpha test samples at vertex `i` of `p`.
    fn uv(&self, p: &Primitive, i: usize) -> Vec2 {
        let raw = if self.tex_coord == 1 {
            p.uv1(i)
        } else {
            p.uvs.get(i).copied().unwrap_or_default()
        };
        self.transform.apply(raw)
    }

    /// Whether integer texel coordinate (i, j) (before wrapping) can pass.
    fn hot(&self, i: i64, j: i64) -> bool {
        let (w, h) = (self.texture.width as i64, self.texture.height as i64);
        let x = self.sampler.wrap_u.texel(i, w);
        let y = self.sampler.wrap_v.texel(j, h);
        let a = self.texture.rgba[((y * w + x) * 4 + 3) as usize];
        a as u16 >= self.min_alpha
    }
}

/// What `trim` did to a primitive.
#[derive(Clone, Debug, Default)]
pub struct Trimmed {
    /// The primitive with its lone cards cut (the same vertex arrays, new vertices after them).
    pub primitive: Primitive,
    /// Cards cut to a smaller polygon.
    pub cut: usize,
    /// Cards left out: none of their texels can pass.
    pub dropped: usize,
    /// Texture-space area kept over the area of the cards cut or dropped.
    pub kept_area: f32,
}

/// A point of a patch: texture coordinates and weights of the patch's base triangle.
#[derive(Clone, Copy, Debug)]
struct Point {
    uv: Vec2,
    w: Vec3,
    /// The original vertex it is, if it is one.
    vertex: Option<u32>,
}

/// `p` with its lone cards cut to where `cut`'s alpha can pass, or None where nothing changed.
pub fn trim(p: &Primitive, cut: &AlphaCut) -> Option<Trimmed> {
    if p.deform.is_some() {
        return None;
    }
    let tris: Vec<[u32; 3]> = p
        .indices
        .chunks_exact(3)
        .map(|t| [t[0], t[1], t[2]])
        .collect();
    let n = p.positions.len() as u32;
    if tris.iter().flatten().any(|&i| i >= n) {
        return None;
    }
    let patches = lone_patches(p, &tris);
    let mut out = Trimmed {
        primitive: p.clone(),
        ..Default::default()
    };
    out.primitive.indices.clear();
    let mut card_area = 0.0;
    let mut kept_area = 0.0;
    let mut changed = false;
    for (t, kind) in tris.iter().zip(&patches) {
        let kind = match kind {
            None => {
                out.primitive.indices.extend(t);
                continue;
            }
            // Drawn with the first of its pair.
            Some(PatchKind::Second) => continue,
            Some(kind) => *kind,
        };
        let whole = |indices: &mut Vec<u32>| {
            indices.extend(t);
            if let PatchKind::Quad(other) = kind {
                indices.extend(&tris[other]);
            }
        };
        let Some(poly) = patch_polygon(p, cut, t, kind) else {
            whole(&mut out.primitive.indices);
            continue;
        };
        let area = polygon_area(&poly);
        match clip_to_alpha(cut, &poly) {
            Clip::Unchanged => whole(&mut out.primitive.indices),
            Clip::Empty => {
                out.dropped += 1;
                card_area += area;
                changed = true;
            }
            Clip::Cut(kept) => {
                out.cut += 1;
                card_area += area;
                kept_area += polygon_area(&kept);
                emit(&mut out.primitive, p, t, &kept);
                changed = true;
            }
        }
    }
    out.kept_area = if card_area > 0.0 {
        kept_area / card_area
    } else {
        1.0
    };
    changed.then_some(out)
}

/// How a triangle takes part in a lone patch.
#[derive(Clone, Copy, Debug, PartialEq)]
enum PatchKind {
    /// A triangle sharing no edge.
    Single,
    /// The first triangle of a pair sharing one edge (the index of the second).
    Quad(usize),
    /// The second triangle of a pair (drawn with the first).
    Second,
}

/// Per triangle: its part in a lone patch, or None where it shares edges otherwise. Edges are
/// matched by position (bit for bit), so split vertices (texture seams) still join triangles.
fn lone_patches(p: &Primitive, tris: &[[u32; 3]]) -> Vec<Option<PatchKind>> {
    let mut ids: HashMap<[u32; 3], u32> = HashMap::new();
    let id: Vec<u32> = p
        .positions
        .iter()
        .map(|v| {
            let next = ids.len() as u32;
            *ids.entry(v.to_array().map(f32::to_bits)).or_insert(next)
        })
        .collect();
    let edge = |a: u32, b: u32| {
        let (a, b) = (id[a as usize], id[b as usize]);
        (a.min(b), a.max(b))
    };
    let mut users: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
    for (k, t) in tris.iter().enumerate() {
        for e in 0..3 {
            users.entry(edge(t[e], t[(e + 1) % 3])).or_default().push(k);
        }
    }
    let mut kinds = vec![None; tris.len()];
    for (k, t) in tris.iter().enumerate() {
        if kinds[k].is_some() {
            continue;
        }
        let keys: Vec<(u32, u32)> = (0..3).map(|e| edge(t[e], t[(e + 1) % 3])).collect();
        if keys[0] == keys[1] || keys[1] == keys[2] || keys[0] == keys[2] || keys[0].0 == keys[0].1
        {
            continue; // degenerate
        }
        let shared: Vec<&Vec<usize>> = keys
            .iter()
            .map(|e| &users[e])
            .filter(|u| u.len() > 1)
            .collect();
        match shared.as_slice() {
            [] => kinds[k] = Some(PatchKind::Single),
            [u] if u.len() == 2 => {
                let other = if u[0] == k { u[1] } else { u[0] };
                let o = tris[other];
                let other_shared = (0..3)
                    .filter(|&e| users[&edge(o[e], o[(e + 1) % 3])].len() > 1)
                    .count();
                if other_shared == 1 && kinds[other].is_none() {
                    kinds[k] = Some(PatchKind::Quad(other));
                    kinds[other] = Some(PatchKind::Second);
                }
            }
            _ => {}
        }
    }
    kinds
}

/// The patch of triangle `t` as a convex polygon in texture space, in `t`'s winding, each point
/// weighted over `t`'s vertices; None where it cannot be cut (a second triangle, a degenerate
/// mapping, or a quad that is not one flat, convex, affinely mapped card).
fn patch_polygon(
    p: &Primitive,
    cut: &AlphaCut,
    t: &[u32; 3],
    kind: PatchKind,
) -> Option<Vec<Point>> {
    let uv = |i: u32| cut.uv(p, i as usize);
    let (a, b, c) = (uv(t[0]), uv(t[1]), uv(t[2]));
    let area2 = (b - a).perp_dot(c - a);
    let texel = 1.0 / (cut.texture.width as f32 * cut.texture.height as f32);
    if !area2.is_finite() || area2.abs() < 1e-3 * texel {
        return None;
    }
    let corner = |k: usize| Point {
        uv: [a, b, c][k],
        w: Vec3::AXES[k],
        vertex: Some(t[k]),
    };
    let mut poly: Vec<Point> = (0..3).map(corner).collect();
    let other = match kind {
        PatchKind::Single => return Some(poly),
        PatchKind::Second => return None,
        PatchKind::Quad(other) => other,
    };
    let o: [u32; 3] = p.indices[other * 3..other * 3 + 3].try_into().ok()?;
    let pos = |i: u32| p.positions[i as usize];
    let alpha = |i: u32| p.color(i as usize).w;
    // The shared edge (t[e], t[e + 1]) must run the other way in `o`, with the same positions,
    // coordinates and vertex alpha; `d` is `o`'s third vertex.
    let same = |i: u32, j: u32| pos(i) == pos(j) && uv(i) == uv(j) && alpha(i) == alpha(j);
    let (e, d) = (0..3).find_map(|e| {
        let (s0, s1) = (t[e], t[(e + 1) % 3]);
        (0..3).find_map(|f| {
            let (q0, q1, q2) = (o[f], o[(f + 1) % 3], o[(f + 2) % 3]);
            (same(q0, s1) && same(q1, s0)).then_some((e, q2))
        })
    })?;
    // d's weights over t from its coordinates; the card must be flat and affinely mapped
    // there: position and vertex alpha as the weights predict.
    let ud = uv(d);
    let w = Vec3::new(
        (b - ud).perp_dot(c - ud),
        (c - ud).perp_dot(a - ud),
        (a - ud).perp_dot(b - ud),
    ) / area2;
    let predicted = pos(t[0]) * w.x + pos(t[1]) * w.y + pos(t[2]) * w.z;
    let size = (pos(t[0]) - pos(t[1]))
        .length()
        .max((pos(t[1]) - pos(t[2])).length())
        .max((pos(t[2]) - pos(d)).length());
    let alpha_predicted = alpha(t[0]) * w.x + alpha(t[1]) * w.y + alpha(t[2]) * w.z;
    if !(predicted - pos(d)).length().is_finite()
        || (predicted - pos(d)).length() > 1e-5 * size
        || (alpha_predicted - alpha(d)).abs() > 1e-5
    {
        return None;
    }
    poly.insert(
        e + 1,
        Point {
            uv: ud,
            w,
            vertex: Some(d),
        },
    );
    // Strictly convex, in t's winding.
    let s = area2.signum();
    let convex = (0..4).all(|k| {
        let (p0, p1, p2) = (poly[k].uv, poly[(k + 1) % 4].uv, poly[(k + 2) % 4].uv);
        (p1 - p0).perp_dot(p2 - p1) * s > 0.0
    });
    convex.then_some(poly)
}

/// Twice the signed area of a polygon in texture space (positive counter-clockwise).
fn twice_signed_area(poly: &[Point]) -> f32 {
    let n = poly.len();
    (0..n)
        .map(|k| poly[k].uv.perp_dot(poly[(k + 1) % n].uv))
        .sum()
}

/// The area of a polygon in texture space.
fn polygon_area(poly: &[Point]) -> f32 {
    0.5 * twice_signed_area(poly).abs()
}

/// What clipping a patch to its alpha gave.
enum Clip {
    /// Every half-plane holds the whole patch.
    Unchanged,
    /// No texel the patch covers can pass.
    Empty,
    /// The part that can pass.
    Cut(Vec<Point>),
}

/// Whether the axis-aligned square `[lo, hi]` overlaps convex polygon `poly` (`sign`: its
/// winding), by separating axes.
fn square_meets(lo: Vec2, hi: Vec2, poly: &[Point], sign: f32) -> bool {
    let n = poly.len();
    (0..n).all(|k| {
        let (a, b) = (poly[k].uv, poly[(k + 1) % n].uv);
        // Outward normal of edge a→b.
        let out = Vec2::new(b.y - a.y, a.x - b.x) * sign;
        let nearest = Vec2::new(
            if out.x > 0.0 { lo.x } else { hi.x },
            if out.y > 0.0 { lo.y } else { hi.y },
        );
        (nearest - a).dot(out) <= 0.0
    })
}

/// Clips convex `poly` to the bounding rectangle of the texels it covers that can pass (each
/// grown to its bilinear reach).
fn clip_to_alpha(cut: &AlphaCut, poly: &[Point]) -> Clip {
    let (w, h) = (cut.texture.width as f32, cut.texture.height as f32);
    let (mut lo, mut hi) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
    for q in poly {
        lo = lo.min(q.uv);
        hi = hi.max(q.uv);
    }
    let sign = twice_signed_area(poly).signum();
    // Texel (i, j)'s bilinear reach: its centre ± one texel.
    let reach = 1.0 + REACH_MARGIN;
    let i0 = (lo.x * w - 0.5 - reach).floor() as i64;
    let i1 = (hi.x * w - 0.5 + reach).ceil() as i64;
    let j0 = (lo.y * h - 0.5 - reach).floor() as i64;
    let j1 = (hi.y * h - 0.5 + reach).ceil() as i64;
    if (i1 - i0 + 1).saturating_mul(j1 - j0 + 1) > MAX_FOOTPRINT || i1 < i0 || j1 < j0 {
        return Clip::Unchanged;
    }
    let square = |i: i64, j: i64| {
        let c = Vec2::new((i as f32 + 0.5) / w, (j as f32 + 0.5) / h);
        let r = Vec2::new(reach / w, reach / h);
        (c - r, c + r)
    };
    // The rectangle: along a row, its first and last texels that can pass reach furthest.
    let (mut keep_lo, mut keep_hi) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
    for j in j0..=j1 {
        let meets = |i: i64| {
            let (a, b) = square(i, j);
            cut.hot(i, j) && square_meets(a, b, poly, sign)
        };
        let Some(first) = (i0..=i1).find(|&i| meets(i)) else {
            continue;
        };
        let last = (first..=i1).rev().find(|&i| meets(i)).unwrap_or(first);
        keep_lo = keep_lo.min(square(first, j).0);
        keep_hi = keep_hi.max(square(last, j).1);
    }
    if keep_lo.x > keep_hi.x {
        return Clip::Empty;
    }
    // Its four sides as half-planes uv · d ≤ e.
    let sides = [
        (Vec2::NEG_X, -keep_lo.x),
        (Vec2::X, keep_hi.x),
        (Vec2::NEG_Y, -keep_lo.y),
        (Vec2::Y, keep_hi.y),
    ];
    let mut out = poly.to_vec();
    let mut changed = false;
    for (d, e) in &sides {
        let (d, e) = (*d, *e);
        let inside = |q: &Point| q.uv.dot(d) <= e;
        if out.iter().all(inside) {
            continue;
        }
        changed = true;
        out = clip_half_plane(&out, d, e);
        if out.len() < 3 {
            return Clip::Empty;
        }
    }
    if !changed {
        return Clip::Unchanged;
    }
    Clip::Cut(out)
}

/// Convex `poly` clipped to the half-plane uv · d ≤ e (Sutherland–Hodgman; new points
/// interpolated along the edges they cut).
fn clip_half_plane(poly: &[Point], d: Vec2, e: f32) -> Vec<Point> {
    let n = poly.len();
    let mut next = Vec::with_capacity(n + 1);
    for k in 0..n {
        let (p0, p1) = (poly[k], poly[(k + 1) % n]);
        let (f0, f1) = (p0.uv.dot(d) - e, p1.uv.dot(d) - e);
        if f0 <= 0.0 {
            next.push(p0);
        }
        if (f0 <= 0.0) != (f1 <= 0.0) {
            let s = f0 / (f0 - f1);
            next.push(Point {
                uv: p0.uv.lerp(p1.uv, s),
                w: p0.w.lerp(p1.w, s),
                vertex: None,
            });
        }
    }
    next
}

/// Appends polygon `poly` (weights over triangle `t` of `src`) to `dst` as a fan of triangles,
/// new vertices interpolated from `t`'s.
fn emit(dst: &mut Primitive, src: &Primitive, t: &[u32; 3], poly: &[Point]) {
    let index: Vec<u32> = poly
        .iter()
        .map(|q| match q.vertex {
            Some(v) => v,
            None => push_vertex(dst, src, t, q.w),
        })
        .collect();
    for k in 1..index.len() - 1 {
        dst.indices.extend([index[0], index[k], index[k + 1]]);
    }
}

/// Appends the vertex of `src` at weights `w` over triangle `t`; returns its index.
fn push_vertex(dst: &mut Primitive, src: &Primitive, t: &[u32; 3], w: Vec3) -> u32 {
    let at = |k: usize| t[k] as usize;
    fn mix<T>(v: &[T], i: [usize; 3], w: Vec3) -> Option<T>
    where
        T: Copy + std::ops::Mul<f32, Output = T> + std::ops::Add<Output = T>,
    {
        Some(*v.get(i[0])? * w.x + *v.get(i[1])? * w.y + *v.get(i[2])? * w.z)
    }
    let i = [at(0), at(1), at(2)];
    let index = dst.positions.len() as u32;
    dst.positions
        .push(mix(&src.positions, i, w).unwrap_or_default());
    if let Some(n) = mix(&src.normals, i, w) {
        dst.normals.push(n.normalize_or_zero());
    }
    if let Some(uv) = mix(&src.uvs, i, w) {
        dst.uvs.push(uv);
    }
    if let Some(tg) = mix::<Vec4>(&src.tangents, i, w) {
        let xyz = tg.truncate().normalize_or_zero();
        dst.tangents.push(xyz.extend(src.tangents[i[0]].w));
    }
    if let Some(c) = mix(&src.colors, i, w) {
        dst.colors.push(c);
    }
    if let Some(uv) = mix(&src.uvs1, i, w) {
        dst.uvs1.push(uv);
    }
    index
}

#[cfg(test)]
mod tests;
