//! Reading motion from glTF: skins, animations, morph targets and per-vertex joints and weights,
//! with a warning (finding code and JSON pointer) for data that cannot be used as it is.

use super::{Animation, Channel, Deform, Interpolation, Keyframes, Local, MorphTarget};
use super::{Property, Rig, RigNode, Skin};
use crate::scene::Scene;
use glam::{Mat4, Quat, Vec3};

/// Most joints a skin may have (a larger one is refused with a warning).
pub const MAX_JOINTS: usize = 65_536;

/// Joints and weights by set, and morph targets, of a primitive with `n` vertices: `None` when
/// it has neither. Influences are normalised (sum 1, with a warning where the file's sums are off
/// by more than 1 %); a vertex whose weights sum to zero keeps the skin's first joint.
pub fn read_deform<'a, 's, F>(
    scene: &mut Scene,
    reader: &gltf::mesh::Reader<'a, 's, F>,
    n: usize,
    at: &str,
    label: &str,
) -> Option<Deform>
where
    F: Clone + Fn(gltf::Buffer<'a>) -> Option<&'s [u8]>,
{
    let mut d = Deform::default();
    let mut set = 0;
    while let (Some(j), Some(w)) = (reader.read_joints(set), reader.read_weights(set)) {
        let j: Vec<[u16; 4]> = j.into_u16().collect();
        let w: Vec<[f32; 4]> = w.into_f32().collect();
        if j.len() != n || w.len() != n {
            break;
        }
        let s = set as usize;
        // Interleave vertex-major: vertex v's sets at v*sets..(v+1)*sets.
        let mut joints = Vec::with_capacity(n * (s + 1));
        let mut weights = Vec::with_capacity(n * (s + 1));
        for v in 0..n {
            joints.extend_from_slice(&d.joints[v * s..(v + 1) * s]);
            joints.push(j[v]);
            weights.extend_from_slice(&d.weights[v * s..(v + 1) * s]);
            weights.push(w[v].map(|x| if x.is_finite() { x.max(0.0) } else { 0.0 }));
        }
        d.joints = joints;
        d.weights = weights;
        d.sets = s + 1;
        set += 1;
    }
    if d.sets > 0 {
        normalise_weights(scene, &mut d, at, label);
    }
    for (k, (p, nrm, t)) in reader.read_morph_targets().enumerate() {
        let target = MorphTarget {
            positions: p
                .map(|i| i.map(Vec3::from_array).collect())
                .unwrap_or_default(),
            normals: nrm
                .map(|i| i.map(Vec3::from_array).collect())
                .unwrap_or_default(),
            tangents: t
                .map(|i| i.map(Vec3::from_array).collect())
                .unwrap_or_default(),
        };
        let ok = |v: &Vec<Vec3>| v.is_empty() || (v.len() == n && v.iter().all(|x| x.is_finite()));
        if ok(&target.positions) && ok(&target.normals) && ok(&target.tangents) {
            d.targets.push(target);
        } else {
            scene.warn(
                "MORPH_TARGET_INVALID",
                format!("{at}/targets/{k}"),
                format!(
                    "{label}: morph target {k} has a wrong count or non-finite values; ignored"
                ),
            );
            d.targets.push(MorphTarget::default());
        }
    }
    (d.sets > 0 || !d.targets.is_empty()).then_some(d)
}

fn normalise_weights(scene: &mut Scene, d: &mut Deform, at: &str, label: &str) {
    let (off, zero) = renormalise(d);
    if off > 0 || zero > 0 {
        scene.warn(
            "SKIN_WEIGHTS_NOT_NORMALIZED",
            format!("{at}/attributes/WEIGHTS_0"),
            format!(
                "{label}: {off} vertices' weights do not sum to 1 (normalised), {zero} sum to 0 \
                 (bound to the skin's first joint)"
            ),
        );
    }
}

/// Scales each vertex's influences to sum 1; a vertex whose weights sum to 0 is bound wholly to
/// the skin's first joint. Returns how many vertices' sums were off by more than 1 % and how
/// many were 0.
fn renormalise(d: &mut Deform) -> (usize, usize) {
    let s = d.sets;
    let (mut off, mut zero) = (0usize, 0usize);
    for v in 0..d.weights.len() / s {
        let run = &mut d.weights[v * s..(v + 1) * s];
        let sum: f32 = run.iter().flatten().sum();
        if sum <= 0.0 {
            zero += 1;
            run.iter_mut().for_each(|w| *w = [0.0; 4]);
            run[0][0] = 1.0;
            d.joints[v * s][0] = 0;
            continue;
        }
        if (sum - 1.0).abs() > 0.01 {
            off += 1;
        }
        for w in run.iter_mut().flatten() {
            *w /= sum;
        }
    }
    (off, zero)
}

/// Checks an animation sampler's accessors before the gltf crate's readers, which assume glTF's
/// types, read them.
fn sampler_types_ok(c: &gltf::animation::Channel) -> bool {
    use gltf::accessor::{DataType as T, Dimensions as D};
    let s = c.sampler();
    let (i, o) = (s.input(), s.output());
    let input_ok = i.data_type() == T::F32 && i.dimensions() == D::Scalar;
    let output_ok = match c.target().property() {
        gltf::animation::Property::Translation | gltf::animation::Property::Scale => {
            o.data_type() == T::F32 && o.dimensions() == D::Vec3
        }
        gltf::animation::Property::Rotation => o.dimensions() == D::Vec4 && o.data_type() != T::U32,
        gltf::animation::Property::MorphTargetWeights => {
            o.dimensions() == D::Scalar && o.data_type() != T::U32
        }
    };
    input_ok && output_ok
}

/// Reads channel `c`'s keyframes (`targets`: the target node's morph target count).
fn read_channel(
    c: &gltf::animation::Channel,
    buffers: &[Vec<u8>],
    targets: usize,
) -> Result<Channel, String> {
    use gltf::animation::util::ReadOutputs as O;
    if !sampler_types_ok(c) {
        return Err("its sampler's accessors have types glTF does not allow".into());
    }
    let reader = c.reader(|b| buffers.get(b.index()).map(|d| &d[..]));
    let times: Vec<f32> = reader.read_inputs().ok_or("no input")?.collect();
    let (property, width, values): (Property, usize, Vec<f32>) =
        match reader.read_outputs().ok_or("no output")? {
            O::Translations(i) => (Property::Translation, 3, i.flatten().collect()),
            O::Scales(i) => (Property::Scale, 3, i.flatten().collect()),
            O::Rotations(r) => (Property::Rotation, 4, r.into_f32().flatten().collect()),
            O::MorphTargetWeights(w) => (
                Property::Weights,
                targets,
                w.into_f32().collect::<Vec<f32>>(),
            ),
        };
    if property == Property::Weights && targets == 0 {
        return Err("it animates morph weights of a node whose mesh has no targets".into());
    }
    let keys = Keyframes {
        interpolation: match c.sampler().interpolation() {
            gltf::animation::Interpolation::Step => Interpolation::Step,
            gltf::animation::Interpolation::Linear => Interpolation::Linear,
            gltf::animation::Interpolation::CubicSpline => Interpolation::CubicSpline,
        },
        times,
        values,
        width,
    };
    keys.validate()?;
    Ok(Channel {
        node: c.target().node().index(),
        property,
        keys,
    })
}

/// Everything the file says about motion, or `None` for a file without animations, skins or
/// morph targets (then nothing about the scene changes). `parents` holds each node's parent
/// from the loader's walk; `light_nodes` and `camera_nodes` the node of each scene light and
/// camera.
pub fn read_rig(
    scene: &mut Scene,
    doc: &gltf::Document,
    buffers: &[Vec<u8>],
    parents: &[Option<usize>],
    light_nodes: Vec<usize>,
    camera_nodes: Vec<usize>,
) -> Option<Rig> {
    let morphs = doc
        .meshes()
        .any(|m| m.primitives().any(|p| p.morph_targets().len() > 0));
    if doc.animations().len() == 0 && doc.skins().len() == 0 && !morphs {
        return None;
    }
    let target_count = |m: &gltf::Mesh| {
        m.primitives()
            .map(|p| p.morph_targets().len())
            .max()
            .unwrap_or(0)
    };
    let mut rig = Rig {
        light_nodes,
        camera_nodes,
        ..Default::default()
    };
    for node in doc.nodes() {
        let (t, r, s) = node.transform().decomposed();
        let targets = node.mesh().map_or(0, |m| target_count(&m));
        let mut weights: Vec<f32> = node
            .weights()
            .or_else(|| node.mesh().and_then(|m| m.weights()))
            .map(|w| w.to_vec())
            .unwrap_or_default();
        weights.resize(targets, 0.0);
        weights
            .iter_mut()
            .for_each(|w| *w = if w.is_finite() { *w } else { 0.0 });
        rig.nodes.push(RigNode {
            parent: parents.get(node.index()).copied().flatten(),
            local: Local {
                matrix: Mat4::from_cols_array_2d(&node.transform().matrix()),
                translation: Vec3::from_array(t),
                rotation: super::sample::unit_quat(Quat::from_array(r)),
                scale: Vec3::from_array(s),
            },
            skin: None,
            weights,
        });
    }
    read_skins(scene, doc, buffers, &mut rig);
    for a in doc.animations() {
        let mut anim = Animation {
            name: a.name().unwrap_or_default().to_string(),
            channels: Vec::new(),
        };
        for c in a.channels() {
            let targets = c.target().node().mesh().map_or(0, |m| target_count(&m));
            match read_channel(&c, buffers, targets) {
                Ok(ch) => anim.channels.push(ch),
                Err(e) => scene.warn(
                    "ANIMATION_CHANNEL_INVALID",
                    format!("/animations/{}/channels/{}", a.index(), c.index()),
                    format!(
                        "animation {} '{}' channel {}: {e}; ignored",
                        a.index(),
                        anim.name,
                        c.index()
                    ),
                ),
            }
        }
        rig.animations.push(anim);
    }
    Some(rig)
}

fn read_skins(scene: &mut Scene, doc: &gltf::Document, buffers: &[Vec<u8>], rig: &mut Rig) {
    for s in doc.skins() {
        let joints: Vec<usize> = s.joints().map(|j| j.index()).collect();
        let at = format!("/skins/{}", s.index());
        // The reader assumes float MAT4 matrices.
        let ibm_ok = s.inverse_bind_matrices().is_none_or(|a| {
            a.data_type() == gltf::accessor::DataType::F32
                && a.dimensions() == gltf::accessor::Dimensions::Mat4
        });
        let mut ibm: Vec<Mat4> = if ibm_ok {
            s.reader(|b| buffers.get(b.index()).map(|d| &d[..]))
                .read_inverse_bind_matrices()
                .map(|m| m.map(|c| Mat4::from_cols_array_2d(&c)).collect())
                .unwrap_or_default()
        } else {
            Vec::new()
        };
        let problem = if !ibm_ok {
            Some("has inverse bind matrices that are not float MAT4".to_string())
        } else if joints.is_empty() {
            Some("has no joints".to_string())
        } else if joints.len() > MAX_JOINTS {
            Some(format!(
                "has {} joints (at most {MAX_JOINTS})",
                joints.len()
            ))
        } else if !ibm.is_empty() && ibm.len() != joints.len() {
            Some(format!(
                "has {} inverse bind matrices for {} joints",
                ibm.len(),
                joints.len()
            ))
        } else if ibm.iter().any(|m| !m.is_finite()) {
            Some("has non-finite inverse bind matrices".to_string())
        } else {
            None
        };
        if let Some(p) = problem {
            scene.warn(
                "SKIN_INVALID",
                at,
                format!("skin {} {p}; its meshes are drawn unskinned", s.index()),
            );
            rig.skins.push(Skin {
                name: s.name().unwrap_or_default().to_string(),
                joints: Vec::new(),
                inverse_bind: Vec::new(),
            });
            continue;
        }
        if ibm.is_empty() {
            ibm = vec![Mat4::IDENTITY; joints.len()];
        }
        rig.skins.push(Skin {
            name: s.name().unwrap_or_default().to_string(),
            joints,
            inverse_bind: ibm,
        });
    }
    for node in doc.nodes() {
        let Some(skin) = node.skin() else { continue };
        if rig.skins[skin.index()].joints.is_empty() {
            continue;
        }
        rig.nodes[node.index()].skin = Some(skin.index());
    }
}

/// Sets joint influences past the skin's joint count to weight 0 (renormalising the rest) and
/// warns; primitives that are skinned but sit on a node without a skin are drawn as stored.
pub fn check_joint_ranges(scene: &mut Scene, rig: &Rig) {
    let mut findings = Vec::new();
    for inst in &scene.instances {
        let Some(node) = inst.node else { continue };
        let joints = rig.nodes[node]
            .skin
            .map(|s| rig.skins[s].joints.len())
            .unwrap_or(0);
        for (pi, p) in scene.meshes[inst.mesh].primitives.iter_mut().enumerate() {
            let Some(d) = p.deform.as_deref_mut().filter(|d| d.skinned()) else {
                continue;
            };
            if joints == 0 {
                findings.push((
                    "SKIN_MISSING",
                    format!("/nodes/{node}"),
                    format!(
                        "node {node}: mesh {} primitive {pi} has JOINTS_0 but the node has no \
                         skin; drawn as stored",
                        inst.mesh
                    ),
                ));
                d.sets = 0;
                d.joints.clear();
                d.weights.clear();
                continue;
            }
            let mut bad = 0usize;
            for (j, w) in d.joints.iter_mut().zip(d.weights.iter_mut()) {
                for k in 0..4 {
                    if j[k] as usize >= joints && w[k] > 0.0 {
                        bad += 1;
                        w[k] = 0.0;
                        j[k] = 0;
                    }
                }
            }
            if bad > 0 {
                renormalise(d);
                findings.push((
                    "SKIN_JOINT_OUT_OF_RANGE",
                    format!("/nodes/{node}"),
                    format!(
                        "node {node}: {bad} influences name joints past the skin's {joints}; \
                         their weight is dropped"
                    ),
                ));
            }
        }
    }
    for (code, at, msg) in findings {
        scene.warn(code, at, msg);
    }
}
