//! Triangle clusters with normal cones, so that the parts of a mesh whose faces all point away
//! from the eye (or the light) are not drawn at all. Back-face culling in the rasteriser happens
//! after vertex processing and triangle setup, which llvmpipe runs on one thread; a cluster
//! skipped on the CPU costs neither. Clusters are meshoptimizer's meshlets (`meshopt`), written
//! back as one index list per primitive so that a run of visible clusters is one draw.

use glam::Vec3;

/// Primitives with fewer triangles stay one draw (the cone test would save too little).
pub const MIN_TRIANGLES: usize = 1024;
/// meshoptimizer's recommended meshlet limits.
const MAX_VERTICES: usize = 64;
const MAX_TRIANGLES: usize = 124;
/// How much meshlet building favours narrow normal cones over compact clusters.
const CONE_WEIGHT: f32 = 0.5;

/// A cluster: a range of the primitive's (rewritten) index list and the cone holding its faces'
/// normals.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cluster {
    /// First index, relative to the primitive's first index.
    pub first: u32,
    /// Index count.
    pub count: u32,
    apex: Vec3,
    axis: Vec3,
    cutoff: f32,
}

impl Cluster {
    /// Every triangle faces away from a perspective eye at `eye` (same space as the positions).
    pub fn back_facing_from(&self, eye: Vec3) -> bool {
        let v = (self.apex - eye).normalize_or_zero();
        v != Vec3::ZERO && v.dot(self.axis) >= self.cutoff
    }

    /// Every triangle faces away from a light (or orthographic eye) looking along `dir`.
    pub fn back_facing_along(&self, dir: Vec3) -> bool {
        let v = dir.normalize_or_zero();
        v != Vec3::ZERO && v.dot(self.axis) >= self.cutoff
    }
}

/// Splits a primitive into clusters: returns its index list reordered cluster by cluster, and the
/// clusters; None for a primitive under `MIN_TRIANGLES` triangles or with an index out of range.
pub fn build(positions: &[Vec3], indices: &[u32]) -> Option<(Vec<u32>, Vec<Cluster>)> {
    if indices.len() / 3 < MIN_TRIANGLES || indices.iter().any(|&i| i as usize >= positions.len()) {
        return None;
    }
    let data: &[u8] = bytemuck::cast_slice(positions);
    let adapter = meshopt::VertexDataAdapter::new(data, std::mem::size_of::<Vec3>(), 0).ok()?;
    let tris = &indices[..indices.len() / 3 * 3];
    let meshlets =
        meshopt::build_meshlets(tris, &adapter, MAX_VERTICES, MAX_TRIANGLES, CONE_WEIGHT);
    let mut out = Vec::with_capacity(tris.len());
    let mut clusters = Vec::with_capacity(meshlets.len());
    for m in meshlets.iter() {
        let first = out.len() as u32;
        out.extend(m.triangles.iter().map(|&t| m.vertices[t as usize]));
        let b = meshopt::compute_meshlet_bounds(m, &adapter);
        clusters.push(Cluster {
            first,
            count: out.len() as u32 - first,
            apex: Vec3::from(b.cone_apex),
            axis: Vec3::from(b.cone_axis),
            cutoff: b.cone_cutoff,
        });
    }
    (out.len() == tris.len()).then_some((out, clusters))
}

/// The runs of consecutive clusters that are not `hidden`, as (first index, index count) relative
/// to the primitive, merged so that each run is one draw.
pub fn visible_runs(
    clusters: &[Cluster],
    mut hidden: impl FnMut(&Cluster) -> bool,
) -> Vec<(u32, u32)> {
    let mut runs: Vec<(u32, u32)> = Vec::new();
    for c in clusters {
        if hidden(c) {
            continue;
        }
        match runs.last_mut() {
            Some(r) if r.0 + r.1 == c.first => r.1 += c.count,
            _ => runs.push((c.first, c.count)),
        }
    }
    runs
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::built::shapes::uv_sphere;

    /// A triangle faces `eye` when the eye is on the side its counter-clockwise winding faces.
    fn faces(p: &[Vec3], t: &[u32], eye: Vec3) -> bool {
        let [a, b, c] = [p[t[0] as usize], p[t[1] as usize], p[t[2] as usize]];
        (b - a).cross(c - a).dot(eye - a) > 0.0
    }

    #[test]
    fn culled_clusters_hold_only_back_faces() {
        let s = uv_sphere(1.0, 64, 32);
        let (idx, clusters) = build(&s.positions, &s.indices).expect("large enough");
        // The same triangles, reordered.
        let mut a: Vec<[u32; 3]> = s.indices.chunks(3).map(|t| [t[0], t[1], t[2]]).collect();
        let mut b: Vec<[u32; 3]> = idx.chunks(3).map(|t| [t[0], t[1], t[2]]).collect();
        for t in a.iter_mut().chain(b.iter_mut()) {
            let m = (0..3).min_by_key(|&i| t[i]).unwrap();
            t.rotate_left(m);
        }
        a.sort_unstable();
        b.sort_unstable();
        assert_eq!(a, b);
        for eye in [
            Vec3::new(0.0, 0.0, 3.0),
            Vec3::new(2.0, 1.5, -1.2),
            Vec3::new(0.0, 1.05, 0.0),
        ] {
            let mut culled_tris = 0;
            for c in clusters.iter().filter(|c| c.back_facing_from(eye)) {
                let tris = &idx[c.first as usize..(c.first + c.count) as usize];
                for t in tris.chunks(3) {
                    assert!(
                        !faces(&s.positions, t, eye),
                        "a culled cluster held a front face"
                    );
                }
                culled_tris += tris.len() / 3;
            }
            // Measured: 50.6 % (3 radii away on the axis), 47.8 % (off axis), 65.0 % (just above
            // the pole, where the eye sees only a small cap).
            let share = culled_tris as f32 / (idx.len() / 3) as f32;
            assert!(share > 0.45, "{eye}: culled {share}");
        }
        // A light along −z: clusters facing +z are lit, never culled.
        let dir = Vec3::NEG_Z;
        let far_eye = Vec3::Z * 1e6;
        for c in clusters.iter().filter(|c| c.back_facing_along(dir)) {
            for t in idx[c.first as usize..(c.first + c.count) as usize].chunks(3) {
                assert!(!faces(&s.positions, t, far_eye));
            }
        }
        // Runs merge neighbours and cover exactly the visible clusters.
        let runs = visible_runs(&clusters, |c| c.back_facing_from(Vec3::Z * 3.0));
        let total: u32 = runs.iter().map(|r| r.1).sum();
        let expected: u32 = clusters
            .iter()
            .filter(|c| !c.back_facing_from(Vec3::Z * 3.0))
            .map(|c| c.count)
            .sum();
        assert_eq!(total, expected);
        assert!(runs.len() < clusters.len());
        // Small meshes stay one draw.
        let small = uv_sphere(1.0, 8, 4);
        assert!(build(&small.positions, &small.indices).is_none());
    }
}
