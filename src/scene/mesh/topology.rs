//! Mesh topology checks that decide how much work a mesh needs.

use glam::{Vec3, Vec4};
use std::collections::HashMap;

/// True when the triangles form closed, consistently wound surfaces: after welding vertices at
/// equal positions (meshes are split at UV and normal seams; equal within 1e-6 of the extent), every edge is used exactly twice,
/// once in each direction. Seen from outside such a mesh only its front faces are nearest, so a
/// double-sided material can cull back faces without changing the image while the viewpoint is
/// outside it. Degenerate triangles (two corners at one position) are ignored; no triangle → false.
pub fn is_closed(positions: &[Vec3], indices: &[u32]) -> bool {
    // Weld on a grid of 1e-6 of the extent: seam copies computed separately (sin 2π ≠ sin 0)
    // differ in the last bits. A pair split by a cell boundary only makes the mesh look open,
    // which costs speed, never pixels.
    let b = crate::math::Aabb::from_points(positions.iter().copied());
    let cell = (b.diagonal() * 1e-6).max(f32::MIN_POSITIVE) as f64;
    let mut ids: HashMap<[i64; 3], u32> = HashMap::with_capacity(positions.len());
    let welded: Vec<u32> = positions
        .iter()
        .map(|p| {
            let key = p.to_array().map(|c| (c as f64 / cell).round() as i64);
            let next = ids.len() as u32;
            *ids.entry(key).or_insert(next)
        })
        .collect();
    let mut edges: HashMap<(u32, u32), u32> = HashMap::with_capacity(indices.len());
    let mut triangles = 0usize;
    for t in indices.chunks_exact(3) {
        let Some(v) = t
            .iter()
            .map(|&i| welded.get(i as usize).copied())
            .collect::<Option<Vec<u32>>>()
        else {
            return false;
        };
        if v[0] == v[1] || v[1] == v[2] || v[0] == v[2] {
            continue;
        }
        triangles += 1;
        for (a, b) in [(v[0], v[1]), (v[1], v[2]), (v[2], v[0])] {
            let n = edges.entry((a, b)).or_insert(0);
            *n += 1;
            if *n > 1 {
                return false; // the same directed edge twice: inconsistent winding or non-manifold
            }
        }
    }
    triangles > 0 && edges.keys().all(|&(a, b)| edges.contains_key(&(b, a)))
}

/// The plane `(n, w)` (unit `n`, `n·p + w = 0`) holding every vertex the triangles use, within
/// 1e-6 of the mesh's extent, or None when the mesh is not flat (or has no triangle of area).
/// A flat caster can only shadow what lies on the far side of its plane from the light, which lets
/// the shadow pass skip a ground plane that has nothing beneath it.
pub fn plane_of(positions: &[Vec3], indices: &[u32]) -> Option<Vec4> {
    let used = || {
        indices
            .iter()
            .filter_map(|&i| positions.get(i as usize).copied())
    };
    let b = crate::math::Aabb::from_points(used());
    // Newell's normal: the sum of the triangles' area vectors (robust to slivers).
    let mut sum = glam::DVec3::ZERO;
    for t in indices.chunks_exact(3) {
        let [a, b2, c] = [t[0], t[1], t[2]].map(|i| positions.get(i as usize).copied());
        let (Some(a), Some(b2), Some(c)) = (a, b2, c) else {
            return None;
        };
        sum += (b2 - a).as_dvec3().cross((c - a).as_dvec3());
    }
    let n = sum.normalize_or_zero();
    if n == glam::DVec3::ZERO || !b.min.is_finite() {
        return None;
    }
    let centre = b.center().as_dvec3();
    let tolerance = (b.diagonal() as f64 * 1e-6).max(1e-30);
    let flat = used().all(|p| (p.as_dvec3() - centre).dot(n).abs() <= tolerance);
    flat.then(|| n.as_vec3().extend(-n.dot(centre) as f32))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::built::shapes::{cuboid, plane, quad, uv_sphere};

    #[test]
    fn closed_shapes_and_open_ones() {
        let b = cuboid(Vec3::new(1.0, 2.0, 3.0));
        assert!(
            is_closed(&b.positions, &b.indices),
            "box (split at face seams)"
        );
        let s = uv_sphere(1.0, 16, 8);
        assert!(
            is_closed(&s.positions, &s.indices),
            "UV sphere (seam, poles)"
        );
        let q = quad(1.0, 1.0);
        assert!(!is_closed(&q.positions, &q.indices), "a quad is open");
        let p = plane(2.0, 1.0);
        assert!(!is_closed(&p.positions, &p.indices), "a plane is open");
        // A box missing one triangle is open; one with a flipped triangle is inconsistent.
        assert!(!is_closed(&b.positions, &b.indices[3..]));
        let mut flipped = b.indices.clone();
        flipped.swap(0, 1);
        assert!(!is_closed(&b.positions, &flipped));
        // Two boxes in one primitive (disjoint closed parts) are closed.
        let mut two = b.positions.clone();
        two.extend(b.positions.iter().map(|p| *p + Vec3::X * 10.0));
        let mut idx = b.indices.clone();
        idx.extend(b.indices.iter().map(|i| i + b.positions.len() as u32));
        assert!(is_closed(&two, &idx));
        assert!(!is_closed(&[], &[]));
    }

    #[test]
    fn flat_meshes_have_a_plane() {
        // The shapes' plane lies at y = 0 facing +y.
        let p = plane(2.0, 1.0);
        let pl = plane_of(&p.positions, &p.indices).expect("a plane is flat");
        assert!(
            (pl - Vec4::new(0.0, 1.0, 0.0, 0.0)).abs().max_element() < 1e-6,
            "{pl}"
        );
        // Moved and tilted: the plane follows.
        let m = glam::Mat4::from_rotation_x(0.3) * glam::Mat4::from_translation(Vec3::Y * 2.0);
        let moved: Vec<Vec3> = p.positions.iter().map(|&v| m.transform_point3(v)).collect();
        let pl = plane_of(&moved, &p.indices).expect("still flat");
        for v in &moved {
            assert!((pl.truncate().dot(*v) + pl.w).abs() < 1e-5);
        }
        // A box, a sphere and a plane with one vertex lifted by 1e-4 of its size are not flat.
        let b = cuboid(Vec3::ONE);
        assert!(plane_of(&b.positions, &b.indices).is_none());
        let s = uv_sphere(1.0, 8, 4);
        assert!(plane_of(&s.positions, &s.indices).is_none());
        let mut bent = p.positions.clone();
        bent[0].y += 2.0 * 1e-4;
        assert!(plane_of(&bent, &p.indices).is_none());
        assert!(plane_of(&[], &[]).is_none());
    }
}
