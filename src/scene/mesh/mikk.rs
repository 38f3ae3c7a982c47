//! MikkTSpace tangents for a primitive whose normal map needs them and whose file has none.

use crate::scene::mesh::tangents::fallback_tangent;
use crate::scene::Primitive;
use glam::{Vec2, Vec3, Vec4};
use std::collections::HashMap;

struct Unwelded {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uvs: Vec<Vec2>,
    tangents: Vec<Vec4>,
    /// Vertex colours (white for a primitive without): welded vertices keep theirs.
    colors: Vec<Vec4>,
    /// TEXCOORD_1 (set 0's for a primitive without).
    uvs1: Vec<Vec2>,
}

impl mikktspace::Geometry for Unwelded {
    fn num_faces(&self) -> usize {
        self.positions.len() / 3
    }
    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }
    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.positions[face * 3 + vert].to_array()
    }
    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        self.normals[face * 3 + vert].to_array()
    }
    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        // glTF's v runs down the image while its tangent space's +Y (and the stored-tangent
        // convention, bitangent = w·(n × t)) points up: flip v so MikkTSpace agrees with it.
        let uv = self.uvs[face * 3 + vert];
        [uv.x, 1.0 - uv.y]
    }
    fn set_tangent_encoded(&mut self, tangent: [f32; 4], face: usize, vert: usize) {
        self.tangents[face * 3 + vert] = Vec4::from_array(tangent);
    }
}

/// The bits that must match for corner `k` of `g` (with tangent `t`) to share a vertex with
/// another: position, normal, uvs, tangent, colour and `source` (0, or the source vertex where
/// only corners of one source may weld).
fn weld_key(g: &Unwelded, k: usize, t: Vec4, source: u32) -> [u32; 19] {
    [
        g.positions[k].x.to_bits(),
        g.positions[k].y.to_bits(),
        g.positions[k].z.to_bits(),
        g.normals[k].x.to_bits(),
        g.normals[k].y.to_bits(),
        g.normals[k].z.to_bits(),
        g.uvs[k].x.to_bits(),
        g.uvs[k].y.to_bits(),
        t.x.to_bits(),
        t.y.to_bits(),
        t.z.to_bits(),
        t.w.to_bits(),
        g.colors[k].x.to_bits(),
        g.colors[k].y.to_bits(),
        g.colors[k].z.to_bits(),
        g.colors[k].w.to_bits(),
        g.uvs1[k].x.to_bits(),
        g.uvs1[k].y.to_bits(),
        source,
    ]
}

/// Generates MikkTSpace tangents (the glTF-specified algorithm) for `p`, with w such that
/// w·(n × t) points up the image (glTF's convention, as in its sample models); splitting vertices where
/// the tangent frame differs (UV seams, mirrored halves) and merging identical ones again.
/// Returns false when generation failed (then tangents are set from the normal alone).
pub fn generate_mikktspace(p: &mut Primitive) -> bool {
    let n = p.indices.len();
    let mut g = Unwelded {
        positions: Vec::with_capacity(n),
        normals: Vec::with_capacity(n),
        uvs: Vec::with_capacity(n),
        tangents: vec![Vec4::ZERO; n],
        colors: Vec::with_capacity(n),
        uvs1: Vec::with_capacity(n),
    };
    let colored = !p.colors.is_empty();
    let second_set = !p.uvs1.is_empty();
    for &i in &p.indices {
        let i = i as usize;
        g.positions.push(p.positions[i]);
        g.normals.push(p.normals[i]);
        g.uvs.push(p.uvs[i]);
        g.colors.push(p.color(i));
        g.uvs1.push(p.uv1(i));
    }
    let ok = mikktspace::generate_tangents(&mut g);
    if !ok {
        p.tangents = p.normals.iter().map(|n| fallback_tangent(*n)).collect();
        return false;
    }
    // Weld identical (position, normal, uvs, tangent, colour) vertices back together; a
    // primitive that skins or morphs welds only corners of the same source vertex (two vertices
    // alike at rest may be bound to different joints or move apart under a target).
    let keep_sources = p.deform.is_some();
    let mut sources: Vec<u32> = Vec::new();
    let mut map: HashMap<[u32; 19], u32> = HashMap::new();
    let (mut pos, mut nor, mut uv, mut tan, mut idx) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let (mut col, mut uv1) = (Vec::new(), Vec::new());
    for k in 0..n {
        let mut t = g.tangents[k];
        if !t.is_finite() || t.truncate().length_squared() < 1e-12 {
            t = fallback_tangent(g.normals[k]);
        }
        let key = weld_key(&g, k, t, if keep_sources { p.indices[k] } else { 0 });
        let id = *map.entry(key).or_insert_with(|| {
            sources.push(p.indices[k]);
            pos.push(g.positions[k]);
            nor.push(g.normals[k]);
            uv.push(g.uvs[k]);
            tan.push(t);
            col.push(g.colors[k]);
            uv1.push(g.uvs1[k]);
            (pos.len() - 1) as u32
        });
        idx.push(id);
    }
    p.positions = pos;
    p.normals = nor;
    p.uvs = uv;
    p.tangents = tan;
    p.colors = if colored { col } else { Vec::new() };
    p.uvs1 = if second_set { uv1 } else { Vec::new() };
    p.indices = idx;
    if let Some(d) = p.deform.as_deref_mut() {
        d.remap(&sources);
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad(mirror: bool) -> Primitive {
        let u = |x: f32| if mirror { 1.0 - x } else { x };
        Primitive {
            positions: vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
            ],
            normals: vec![Vec3::Z; 4],
            uvs: vec![
                Vec2::new(u(0.0), 1.0),
                Vec2::new(u(1.0), 1.0),
                Vec2::new(u(1.0), 0.0),
                Vec2::new(u(0.0), 0.0),
            ],
            tangents: vec![],
            indices: vec![0, 1, 2, 0, 2, 3],
            material: 0,
            has_uvs: true,
            colors: Vec::new(),
            uvs1: Vec::new(),
            deform: None,
        }
    }

    #[test]
    fn tangent_follows_u_and_mirrors_sign() {
        let mut q = quad(false);
        assert!(generate_mikktspace(&mut q));
        for t in &q.tangents {
            assert!(t.truncate().abs_diff_eq(Vec3::X, 1e-5), "{t}");
            assert_eq!(t.w, 1.0);
        }
        assert_eq!(q.positions.len(), 4, "welded back");
        let mut m = quad(true);
        assert!(generate_mikktspace(&mut m));
        for t in &m.tangents {
            // u runs along −X: n × t = Z × −X = −Y, but up the image is still +Y: mirrored, w = −1.
            assert!(t.truncate().abs_diff_eq(-Vec3::X, 1e-5), "{t}");
            assert_eq!(t.w, -1.0);
        }
    }

    #[test]
    fn welding_keeps_vertex_colours() {
        let mut q = quad(false);
        let corner = |p: Vec3| Vec4::new(p.x, p.y, 0.5, 1.0);
        q.colors = q.positions.iter().map(|&p| corner(p)).collect();
        assert!(generate_mikktspace(&mut q));
        assert_eq!(q.colors.len(), q.positions.len());
        for (p, c) in q.positions.iter().zip(&q.colors) {
            assert_eq!(*c, corner(*p));
        }
        // Without colours, none are made up.
        let mut q = quad(false);
        assert!(generate_mikktspace(&mut q));
        assert!(q.colors.is_empty());
    }
}
