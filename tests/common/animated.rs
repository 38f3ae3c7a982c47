//! The test suite's animated models, written by the project's code: a two-joint skinned bar, a
//! node hierarchy animated with STEP, LINEAR and CUBICSPLINE keys, and a cube with two morph
//! targets and animated weights. Their definitions are in the doc comments; the tests compute
//! where things must be from those, not from the code under test.

use super::gltf_builder::{Builder, Container, U16};
use glam::{Mat4, Quat, Vec3};
use serde_json::json;
use std::path::{Path, PathBuf};

/// Writes the three animated models into `dir` (the bar animated, "bend").
pub fn write_animated(dir: &Path) -> Vec<PathBuf> {
    vec![
        skinned_bar(dir, "skinned_bar", 0.0, true),
        hierarchy(dir),
        morph_cube(dir),
    ]
}

/// A square prism 0.3 across around the Y axis with rings at `ys`, flat-shaded (each side and
/// cap has its own vertices and normal); caps at both ends. Returns positions, normals, indices
/// and each vertex's ring.
fn prism(ys: &[f32]) -> (Vec<f32>, Vec<f32>, Vec<u32>, Vec<usize>) {
    let h = 0.15;
    let corners = [(-h, h), (h, h), (h, -h), (-h, -h)];
    let (mut pos, mut nrm, mut idx, mut ring) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut vertex = |p: [f32; 3], n: [f32; 3], r: usize| {
        pos.extend_from_slice(&p);
        nrm.extend_from_slice(&n);
        ring.push(r);
        (ring.len() - 1) as u32
    };
    for k in 0..4 {
        let ((x0, z0), (x1, z1)) = (corners[k], corners[(k + 1) % 4]);
        let n = [(x0 + x1) / (2.0 * h), 0.0, (z0 + z1) / (2.0 * h)];
        let column: Vec<(u32, u32)> = ys
            .iter()
            .enumerate()
            .map(|(r, &y)| (vertex([x0, y, z0], n, r), vertex([x1, y, z1], n, r)))
            .collect();
        for w in column.windows(2) {
            let ((a, b), (c, d)) = (w[0], w[1]);
            idx.extend_from_slice(&[a, b, d, a, d, c]);
        }
    }
    let last = ys.len() - 1;
    for (r, y, up) in [(0, ys[0], -1.0f32), (last, ys[last], 1.0)] {
        let v: Vec<u32> = corners
            .iter()
            .map(|&(x, z)| vertex([x, y, z], [0.0, up, 0.0], r))
            .collect();
        if up > 0.0 {
            idx.extend_from_slice(&[v[0], v[1], v[2], v[0], v[2], v[3]]);
        } else {
            idx.extend_from_slice(&[v[0], v[2], v[1], v[0], v[3], v[2]]);
        }
    }
    (pos, nrm, idx, ring)
}

/// The two-joint bar: rings at y = 0, 1, 2; the lower two on joint 0 (at the origin), the top
/// ring on joint 1 (1 up, child of joint 0). Joint 1 rests at `rest_degrees` about Z and, with
/// `animate`, turns linearly from 0° at t = 0 to 90° at t = 1 ("bend").
pub fn skinned_bar(dir: &Path, name: &str, rest_degrees: f32, animate: bool) -> PathBuf {
    let mut b = Builder::default();
    let (pos, nrm, idx, ring) = prism(&[0.0, 1.0, 2.0]);
    let p = b.floats(&pos, 3, "VEC3");
    let n = b.floats(&nrm, 3, "VEC3");
    let i = b.indices(&idx, U16);
    let influences: Vec<[u16; 4]> = ring
        .iter()
        .map(|&r| if r < 2 { [0, 0, 0, 0] } else { [1, 0, 0, 0] })
        .collect();
    let joints = b.joints(&influences);
    let weights: Vec<f32> = ring.iter().flat_map(|_| [1.0, 0.0, 0.0, 0.0]).collect();
    let wts = b.floats(&weights, 4, "VEC4");
    let m = b.mesh(
        "bar",
        vec![
            json!({"attributes": {"POSITION": p, "NORMAL": n, "JOINTS_0": joints, "WEIGHTS_0": wts},
                    "indices": i}),
        ],
    );
    // Joint 0 at the origin; joint 1 one unit up. Inverse bind matrices undo the bind pose.
    let ibm: Vec<f32> = Mat4::IDENTITY
        .to_cols_array()
        .into_iter()
        .chain(Mat4::from_translation(Vec3::new(0.0, -1.0, 0.0)).to_cols_array())
        .collect();
    let ibm = b.data(&ibm, 16, "MAT4");
    b.node(json!({"name": "bar", "mesh": m, "skin": 0}), true);
    let rest = Quat::from_rotation_z(rest_degrees.to_radians());
    b.node(json!({"name": "lower", "children": [2]}), true);
    b.node(
        json!({"name": "upper", "translation": [0.0, 1.0, 0.0], "rotation": rest.to_array()}),
        false,
    );
    b.skin(json!({"joints": [1, 2], "inverseBindMatrices": ibm}));
    if animate {
        let t = b.data(&[0.0, 1.0], 1, "SCALAR");
        let q = Quat::from_rotation_z(90f32.to_radians());
        let r: Vec<f32> = Quat::IDENTITY
            .to_array()
            .into_iter()
            .chain(q.to_array())
            .collect();
        let r = b.data(&r, 4, "VEC4");
        b.animation(json!({
            "name": "bend",
            "samplers": [{"input": t, "output": r, "interpolation": "LINEAR"}],
            "channels": [{"sampler": 0, "target": {"node": 2, "path": "rotation"}}]
        }));
    }
    b.write(dir, name, Container::Glb)
}

/// A cube of side `s` centred at the origin: 8 shared vertices.
fn cube(s: f32) -> (Vec<f32>, Vec<u32>) {
    let h = s / 2.0;
    let mut pos = Vec::new();
    for k in 0..8 {
        let c = |bit: u32| if k & bit != 0 { h } else { -h };
        pos.extend_from_slice(&[c(1), c(2), c(4)]);
    }
    // Faces (outward, counter-clockwise): -X, +X, -Y, +Y, -Z, +Z.
    let faces = [
        [0, 4, 6, 2],
        [1, 3, 7, 5],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 2, 3, 1],
        [4, 5, 7, 6],
    ];
    let idx = faces
        .iter()
        .flat_map(|f| [f[0], f[1], f[2], f[0], f[2], f[3]])
        .collect();
    (pos, idx)
}

/// An unlit material of colour `rgb`.
fn unlit(b: &mut Builder, rgb: [f32; 3]) -> usize {
    b.use_extension("KHR_materials_unlit");
    b.material(json!({
        "pbrMetallicRoughness": {"baseColorFactor": [rgb[0], rgb[1], rgb[2], 1.0]},
        "extensions": {"KHR_materials_unlit": {}}
    }))
}

/// The hierarchy: a red cube "root" moved by STEP from x = -1 (t < 1) to x = 1; a green cube
/// 1.2 above it turned by LINEAR rotation about Z from 0° (t = 0) to 90° (t = 2); a blue cube
/// 1.2 above that in the green one's frame, moved by CUBICSPLINE from (0, 1.2, 0) back to
/// (0, 1.2, 0) with an out-tangent (0.5, 0, 0) and an in-tangent (-0.5, 0, 0).
pub fn hierarchy(dir: &Path) -> PathBuf {
    let mut b = Builder::default();
    let (pos, idx) = cube(0.5);
    let p = b.floats(&pos, 3, "VEC3");
    let i = b.indices(&idx, U16);
    let meshes: Vec<usize> = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
        .iter()
        .enumerate()
        .map(|(k, c)| {
            let m = unlit(&mut b, *c);
            b.mesh(
                &format!("cube{k}"),
                vec![json!({"attributes": {"POSITION": p}, "indices": i, "material": m})],
            )
        })
        .collect();
    b.node(
        json!({"name": "root", "mesh": meshes[0], "children": [1]}),
        true,
    );
    b.node(
        json!({"name": "child", "mesh": meshes[1], "translation": [0.0, 1.2, 0.0], "children": [2]}),
        false,
    );
    b.node(
        json!({"name": "grandchild", "mesh": meshes[2], "translation": [0.0, 1.2, 0.0]}),
        false,
    );
    let t01 = b.data(&[0.0, 1.0], 1, "SCALAR");
    let t02 = b.data(&[0.0, 2.0], 1, "SCALAR");
    let step = b.data(&[-1.0, 0.0, 0.0, 1.0, 0.0, 0.0], 3, "VEC3");
    let q = Quat::from_rotation_z(90f32.to_radians());
    let rot: Vec<f32> = Quat::IDENTITY
        .to_array()
        .into_iter()
        .chain(q.to_array())
        .collect();
    let rot = b.data(&rot, 4, "VEC4");
    // CUBICSPLINE: per key in-tangent, value, out-tangent.
    #[rustfmt::skip]
    let cubic = b.data(&[
        0.0, 0.0, 0.0,   0.0, 1.2, 0.0,   0.5, 0.0, 0.0,
        -0.5, 0.0, 0.0,  0.0, 1.2, 0.0,   0.0, 0.0, 0.0,
    ], 3, "VEC3");
    b.animation(json!({
        "name": "modes",
        "samplers": [
            {"input": t01, "output": step, "interpolation": "STEP"},
            {"input": t02, "output": rot, "interpolation": "LINEAR"},
            {"input": t02, "output": cubic, "interpolation": "CUBICSPLINE"}
        ],
        "channels": [
            {"sampler": 0, "target": {"node": 0, "path": "translation"}},
            {"sampler": 1, "target": {"node": 1, "path": "rotation"}},
            {"sampler": 2, "target": {"node": 2, "path": "translation"}}
        ]
    }));
    b.write(dir, "hierarchy", Container::External)
}

/// The morphing cube: side 1; target 0 raises the four top vertices by 1, target 1 moves the
/// four +X vertices out by 1. The mesh's default weights are (0.5, 0); "grow" animates them
/// linearly from (0, 0) at t = 0 to (1, 1) at t = 1.
pub fn morph_cube(dir: &Path) -> PathBuf {
    let mut b = Builder::default();
    let (pos, idx) = cube(1.0);
    let p = b.floats(&pos, 3, "VEC3");
    let i = b.indices(&idx, U16);
    let delta = |axis: usize| -> Vec<f32> {
        (0..8)
            .flat_map(|k| {
                let mut d = [0.0; 3];
                if pos[k * 3 + axis] > 0.0 {
                    d[axis] = 1.0;
                }
                d
            })
            .collect()
    };
    let up = b.floats(&delta(1), 3, "VEC3");
    let out = b.floats(&delta(0), 3, "VEC3");
    let m = b.mesh(
        "morph",
        vec![json!({"attributes": {"POSITION": p}, "indices": i,
                    "targets": [{"POSITION": up}, {"POSITION": out}]})],
    );
    b.mesh_mut(m)["weights"] = json!([0.5, 0.0]);
    b.node(json!({"name": "morph", "mesh": m}), true);
    let t = b.data(&[0.0, 1.0], 1, "SCALAR");
    let w = b.data(&[0.0, 0.0, 1.0, 1.0], 1, "SCALAR");
    b.animation(json!({
        "name": "grow",
        "samplers": [{"input": t, "output": w, "interpolation": "LINEAR"}],
        "channels": [{"sampler": 0, "target": {"node": 0, "path": "weights"}}]
    }));
    b.write(dir, "morph_cube", Container::Glb)
}
