//! Vertex deformation: morph targets, then linear-blend skinning, on the CPU. The posed vertex
//! stream is what the GPU's passes (every shadow view and the camera), the ray-cast reference,
//! picking and the bounds all read, so they cannot disagree about where a vertex is.

use glam::{Mat3, Mat4, Vec3, Vec4};

/// One morph target's per-vertex displacements (empty where the target lacks the attribute).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MorphTarget {
    /// POSITION displacements.
    pub positions: Vec<Vec3>,
    /// NORMAL displacements.
    pub normals: Vec<Vec3>,
    /// TANGENT (xyz) displacements.
    pub tangents: Vec<Vec3>,
}

/// The undeformed data of a primitive that skins or morphs; `Primitive::positions`, `normals` and
/// `tangents` hold the posed result.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Deform {
    /// Positions as stored.
    pub positions: Vec<Vec3>,
    /// Normals as stored (or computed).
    pub normals: Vec<Vec3>,
    /// Tangents as stored (or generated).
    pub tangents: Vec<Vec4>,
    /// Influences per vertex: `sets` runs of 4 (JOINTS_n, WEIGHTS_n), vertex-major, weights
    /// normalised to sum 1; empty for a primitive that only morphs.
    pub joints: Vec<[u16; 4]>,
    /// The weights matching `joints`.
    pub weights: Vec<[f32; 4]>,
    /// JOINTS_n/WEIGHTS_n sets per vertex.
    pub sets: usize,
    /// Morph targets.
    pub targets: Vec<MorphTarget>,
    /// Whether normals were computed by the loader (then recomputed after morphing).
    pub normals_computed: bool,
}

impl Deform {
    /// Whether the primitive has skinning influences.
    pub fn skinned(&self) -> bool {
        self.sets > 0 && !self.joints.is_empty()
    }

    /// Keeps only vertices `order` (new vertex i = old vertex `order[i]`), as tangent generation
    /// splits and welds them.
    pub fn remap(&mut self, order: &[u32]) {
        let pick3 = |v: &Vec<Vec3>| -> Vec<Vec3> {
            if v.is_empty() {
                Vec::new()
            } else {
                order.iter().map(|&i| v[i as usize]).collect()
            }
        };
        for t in &mut self.targets {
            t.positions = pick3(&t.positions);
            t.normals = pick3(&t.normals);
            t.tangents = pick3(&t.tangents);
        }
        if self.sets > 0 {
            let s = self.sets;
            let mut j = Vec::with_capacity(order.len() * s);
            let mut w = Vec::with_capacity(order.len() * s);
            for &i in order {
                let i = i as usize;
                j.extend_from_slice(&self.joints[i * s..(i + 1) * s]);
                w.extend_from_slice(&self.weights[i * s..(i + 1) * s]);
            }
            self.joints = j;
            self.weights = w;
        }
    }
}

/// Where a deformed primitive's vertices go: positions, normals and tangents.
pub struct Posed {
    /// Positions.
    pub positions: Vec<Vec3>,
    /// Unit normals.
    pub normals: Vec<Vec3>,
    /// Tangents (xyz unit, w the stored sign).
    pub tangents: Vec<Vec4>,
}

/// Applies morph `weights` (missing ones 0) and then, with `joints` (one matrix per skin joint:
/// world_from_joint · inverse bind matrix), linear-blend skinning. Without joints the result is
/// in the primitive's model space; with them, in world space. `indices` are the primitive's, for
/// normals the loader computed (recomputed from the morphed positions).
pub fn deform(d: &Deform, weights: &[f32], joints: Option<&[Mat4]>, indices: &[u32]) -> Posed {
    let mut positions = d.positions.clone();
    let mut normals = d.normals.clone();
    let mut tangents = d.tangents.clone();
    // What changed: only those are renormalised, so a pose that moves nothing gives the stored
    // data back to the bit.
    let (mut morphed, mut normals_moved, mut tangents_moved) = (false, false, false);
    for (t, &w) in d.targets.iter().zip(weights) {
        if w == 0.0 || !w.is_finite() {
            continue;
        }
        morphed |= !t.positions.is_empty();
        normals_moved |= !t.normals.is_empty();
        tangents_moved |= !t.tangents.is_empty();
        add_scaled(&mut positions, &t.positions, w);
        add_scaled(&mut normals, &t.normals, w);
        for (tan, dt) in tangents.iter_mut().zip(&t.tangents) {
            *tan += (*dt * w).extend(0.0);
        }
    }
    if morphed && d.normals_computed {
        normals = super::super::mesh::tangents::compute_smooth_normals(&positions, indices);
    }
    if let Some(joints) = joints.filter(|_| d.skinned()) {
        skin(d, joints, &mut positions, &mut normals, &mut tangents);
        (normals_moved, tangents_moved) = (true, true);
    }
    if normals_moved {
        for n in &mut normals {
            *n = n.try_normalize().unwrap_or(Vec3::Y);
        }
    }
    if tangents_moved {
        for t in &mut tangents {
            let xyz = t.truncate().try_normalize().unwrap_or(Vec3::X);
            *t = xyz.extend(if t.w < 0.0 { -1.0 } else { 1.0 });
        }
    }
    Posed {
        positions,
        normals,
        tangents,
    }
}

fn add_scaled(to: &mut [Vec3], delta: &[Vec3], w: f32) {
    for (v, dv) in to.iter_mut().zip(delta) {
        *v += *dv * w;
    }
}

/// Linear-blend skinning in place: each vertex by the weighted sum of its joints' matrices
/// (normals by the sum's inverse transpose, tangents by its upper 3×3).
fn skin(
    d: &Deform,
    joints: &[Mat4],
    positions: &mut [Vec3],
    normals: &mut [Vec3],
    tangents: &mut [Vec4],
) {
    let s = d.sets;
    for (v, p) in positions.iter_mut().enumerate() {
        let mut m = Mat4::ZERO;
        for k in v * s..(v + 1) * s {
            for (j, w) in d.joints[k].iter().zip(d.weights[k]) {
                if w != 0.0 {
                    if let Some(jm) = joints.get(*j as usize) {
                        m += *jm * w;
                    }
                }
            }
        }
        *p = m.transform_point3(*p);
        let m3 = Mat3::from_mat4(m);
        if let Some(n) = normals.get_mut(v) {
            *n = cofactor(m3) * *n;
        }
        if let Some(t) = tangents.get_mut(v) {
            *t = (m3 * t.truncate()).extend(t.w);
        }
    }
}

/// The cofactor matrix: the inverse transpose times the determinant, so normals keep their side
/// under any invertible map and need no division.
fn cofactor(m: Mat3) -> Mat3 {
    let (a, b, c) = (m.x_axis, m.y_axis, m.z_axis);
    Mat3::from_cols(b.cross(c), c.cross(a), a.cross(b))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bar() -> Deform {
        Deform {
            positions: vec![
                Vec3::ZERO,
                Vec3::new(0.0, 1.0, 0.0),
                Vec3::new(0.0, 2.0, 0.0),
            ],
            normals: vec![Vec3::X; 3],
            tangents: vec![Vec4::new(0.0, 0.0, 1.0, -1.0); 3],
            // Vertex 0 on joint 0, vertex 1 half and half, vertex 2 on joint 1.
            joints: vec![[0, 1, 0, 0], [0, 1, 0, 0], [0, 1, 0, 0]],
            weights: vec![
                [1.0, 0.0, 0.0, 0.0],
                [0.5, 0.5, 0.0, 0.0],
                [0.0, 1.0, 0.0, 0.0],
            ],
            sets: 1,
            targets: Vec::new(),
            normals_computed: false,
        }
    }

    #[test]
    fn skinning_blends_the_joint_matrices() {
        // Joint 1 rotated 90° about Z around the point (0, 1, 0).
        let pivot = Vec3::new(0.0, 1.0, 0.0);
        let rot = Mat4::from_translation(pivot)
            * Mat4::from_rotation_z(90f32.to_radians())
            * Mat4::from_translation(-pivot);
        let posed = deform(&bar(), &[], Some(&[Mat4::IDENTITY, rot]), &[]);
        // Vertex 2 (0, 2, 0) turns to (-1, 1, 0); vertex 1 is on the pivot; vertex 0 stays.
        assert!(posed.positions[0].abs_diff_eq(Vec3::ZERO, 1e-6));
        assert!(posed.positions[1].abs_diff_eq(pivot, 1e-6));
        assert!(posed.positions[2].abs_diff_eq(Vec3::new(-1.0, 1.0, 0.0), 1e-6));
        // Normal X under joint 1 becomes +Y; blended half-way it is (1, 1, 0)/√2.
        assert!(posed.normals[2].abs_diff_eq(Vec3::Y, 1e-6));
        let h = std::f32::consts::FRAC_1_SQRT_2;
        assert!(posed.normals[1].abs_diff_eq(Vec3::new(h, h, 0.0), 1e-6));
        // Tangent Z is unchanged by a rotation about Z and keeps its sign.
        assert_eq!(posed.tangents[2], Vec4::new(0.0, 0.0, 1.0, -1.0));
    }

    #[test]
    fn morph_targets_add_weighted_displacements() {
        let mut d = bar();
        d.sets = 0;
        d.joints.clear();
        d.weights.clear();
        d.targets = vec![
            MorphTarget {
                positions: vec![Vec3::X; 3],
                normals: Vec::new(),
                tangents: Vec::new(),
            },
            MorphTarget {
                positions: vec![Vec3::new(0.0, 0.0, 2.0); 3],
                normals: vec![Vec3::new(-1.0, 1.0, 0.0); 3],
                tangents: Vec::new(),
            },
        ];
        let posed = deform(&d, &[0.5, 0.25], None, &[]);
        assert!(posed.positions[2].abs_diff_eq(Vec3::new(0.5, 2.0, 0.5), 1e-6));
        // n = X + 0.25·(-1, 1, 0) = (0.75, 0.25, 0), normalised.
        assert!(posed.normals[0].abs_diff_eq(Vec3::new(0.75, 0.25, 0.0).normalize(), 1e-6));
        // Zero weights leave the stored shape.
        let rest = deform(&d, &[0.0, 0.0], None, &[]);
        assert_eq!(rest.positions, d.positions);
    }

    #[test]
    fn remap_follows_split_vertices() {
        let mut d = bar();
        d.targets = vec![MorphTarget {
            positions: vec![Vec3::X, Vec3::Y, Vec3::Z],
            ..Default::default()
        }];
        d.remap(&[2, 2, 0]);
        assert_eq!(d.targets[0].positions, vec![Vec3::Z, Vec3::Z, Vec3::X]);
        assert_eq!(d.weights[0], [0.0, 1.0, 0.0, 0.0]);
        assert_eq!(d.weights[2], [1.0, 0.0, 0.0, 0.0]);
    }
}
