//! Repairs: normals computed when missing, tangents from a normal alone (MikkTSpace tangents
//! for a whole primitive are `scene::mesh::mikk`'s).

use glam::{Vec3, Vec4};

/// Smooth, area-weighted vertex normals. Vertices that only touch zero-area triangles get +Y.
pub fn compute_smooth_normals(positions: &[Vec3], indices: &[u32]) -> Vec<Vec3> {
    let mut acc = vec![Vec3::ZERO; positions.len()];
    for tri in indices.chunks_exact(3) {
        let (a, b, c) = (tri[0] as usize, tri[1] as usize, tri[2] as usize);
        let n = (positions[b] - positions[a]).cross(positions[c] - positions[a]);
        if n.is_finite() {
            acc[a] += n;
            acc[b] += n;
            acc[c] += n;
        }
    }
    acc.into_iter()
        .map(|n| n.try_normalize().unwrap_or(Vec3::Y))
        .collect()
}

/// Counts triangles whose area is zero (or not finite).
pub fn count_degenerate(positions: &[Vec3], indices: &[u32]) -> usize {
    indices
        .chunks_exact(3)
        .filter(|t| {
            let (a, b, c) = (
                positions[t[0] as usize],
                positions[t[1] as usize],
                positions[t[2] as usize],
            );
            let n = (b - a).cross(c - a);
            n.length_squared().is_nan() || n.length_squared() <= 0.0 || !n.is_finite()
        })
        .count()
}

/// Any unit tangent perpendicular to `n`, sign +1.
pub fn fallback_tangent(n: Vec3) -> Vec4 {
    let t = if n.x.abs() < 0.9 { Vec3::X } else { Vec3::Y };
    let t = (t - n * n.dot(t)).try_normalize().unwrap_or(Vec3::X);
    t.extend(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn smooth_normals_and_degenerates() {
        let p = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Y * 2.0];
        let n = compute_smooth_normals(&p, &[0, 1, 2, 2, 2, 3]);
        assert!(n[0].abs_diff_eq(Vec3::Z, 1e-6));
        assert_eq!(n[3], Vec3::Y, "only degenerate neighbours");
        assert_eq!(count_degenerate(&p, &[0, 1, 2, 2, 2, 3]), 1);
    }
}
