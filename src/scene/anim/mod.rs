//! Scenes that move: glTF node animation (translation, rotation, scale, morph weights), skins
//! and morph targets. [`Rig`] holds what a loaded file says about motion; [`Rig::pose`] evaluates
//! it at a time into a [`Pose`] (node world matrices, joint matrices, morph weights), and
//! [`Scene::apply_pose`] writes that pose into the scene's instances, lights, cameras and
//! deformed vertices, so the GPU path, the ray-cast reference, `inspect` and picking all see the
//! same posed scene.

mod deform;
pub mod load;
pub mod report;
mod rig;
mod sample;

pub use deform::{deform, Deform, MorphTarget, Posed};
pub use rig::*;
pub use sample::{hermite, slerp, Interpolation, Keyframes};

use super::{Camera, Scene};
use glam::{Mat4, Quat, Vec3};

impl Scene {
    /// Whether anything in the scene can move or deform (animations, skins or morph targets).
    pub fn moves(&self) -> bool {
        self.rig
            .as_ref()
            .is_some_and(|r| !r.animations.is_empty() || !r.skins.is_empty() || self.deforms())
    }

    /// Whether any primitive skins or morphs.
    pub fn deforms(&self) -> bool {
        self.meshes
            .iter()
            .flat_map(|m| &m.primitives)
            .any(|p| p.deform.is_some())
    }

    /// Which instances can move between poses: those whose node or an ancestor any animation
    /// channel targets, and those whose mesh skins or morphs (all false without a rig).
    pub fn moving_instances(&self) -> Vec<bool> {
        let Some(rig) = self.rig.as_deref() else {
            return vec![false; self.instances.len()];
        };
        let mut animated = vec![false; rig.nodes.len()];
        for c in rig.animations.iter().flat_map(|a| &a.channels) {
            if let Some(a) = animated.get_mut(c.node) {
                *a = true;
            }
        }
        // A node moves if it or any ancestor is animated (parent links have no cycle).
        let moves = |mut n: usize| {
            for _ in 0..=rig.nodes.len() {
                if animated[n] {
                    return true;
                }
                match rig.nodes[n].parent {
                    Some(p) => n = p,
                    None => return false,
                }
            }
            false
        };
        self.instances
            .iter()
            .map(|i| {
                let deforms = self.meshes[i.mesh]
                    .primitives
                    .iter()
                    .any(|p| p.deform.is_some());
                deforms || i.node.is_some_and(|n| n < rig.nodes.len() && moves(n))
            })
            .collect()
    }

    /// World bounds of the scene over its motion: its current bounds united with those of every
    /// animation posed at `samples` evenly spaced times (the current bounds alone for a scene
    /// that does not move). What a ground under an animated model is placed by.
    pub fn motion_bounds(&self, samples: usize) -> crate::math::Aabb {
        let mut b = self.bounds();
        let Some(rig) = self.rig.as_deref() else {
            return b;
        };
        // The geometry alone is posed (no textures copied).
        let mut posed = Scene {
            meshes: self.meshes.clone(),
            instances: self.instances.clone(),
            ..Default::default()
        };
        for (i, a) in rig.animations.iter().enumerate() {
            let d = a.duration();
            for k in 0..samples.max(1) {
                let t = d * k as f32 / (samples.max(2) - 1) as f32;
                posed.apply_pose(rig, &rig.pose(&Playing::One(i), t), true);
                b = b.union(&posed.bounds());
            }
        }
        b
    }

    /// Poses the scene at time `t` of `playing` (no-op for a scene without a rig).
    pub fn pose_at(&mut self, playing: &Playing, t: f32) {
        if let Some(rig) = self.rig.clone() {
            let pose = rig.pose(playing, t);
            self.apply_pose(&rig, &pose, true);
        }
    }

    /// Writes `pose` into the scene: deformed vertices (morphs, then skins: a skinned mesh is
    /// placed by its joints, its own node's transform ignored, as the spec says) and, with
    /// `rigid`, the instances', lights' and cameras' transforms.
    pub fn apply_pose(&mut self, rig: &Rig, pose: &Pose, rigid: bool) {
        for ii in 0..self.instances.len() {
            let inst = self.instances[ii];
            let Some(node) = inst.node.filter(|&n| n < rig.nodes.len()) else {
                continue;
            };
            let skin = rig.nodes[node].skin.and_then(|s| pose.joints.get(s));
            let mesh = &mut self.meshes[inst.mesh];
            let mut skinned = false;
            for p in &mut mesh.primitives {
                let Some(d) = p.deform.as_deref() else {
                    continue;
                };
                let joints = skin.map(|j| &j[..]).filter(|_| d.skinned());
                skinned |= joints.is_some();
                let posed = deform(d, &pose.weights[node], joints, &p.indices);
                p.positions = posed.positions;
                p.normals = posed.normals;
                p.tangents = posed.tangents;
            }
            if skinned {
                self.instances[ii].world_from_model = Mat4::IDENTITY;
            } else if rigid {
                self.instances[ii].world_from_model = pose.world[node];
            }
        }
        if !rigid {
            return;
        }
        for (l, &n) in self.lights.iter_mut().zip(&rig.light_nodes) {
            let (_, rot, pos) = pose.world[n].to_scale_rotation_translation();
            l.position = pos;
            l.direction = (rot * -Vec3::Z).normalize_or_zero();
        }
        for (c, &n) in self.cameras.iter_mut().zip(&rig.camera_nodes) {
            let (_, rot, pos) = pose.world[n].to_scale_rotation_translation();
            *c = Camera {
                world_from_view: Mat4::from_rotation_translation(rot, pos),
                ..*c
            };
        }
    }
}

/// Adds `primitive` to `scene` as a caster moving through `keys` (time in seconds, position of
/// its origin), linearly, as animation "move" (the scene gets a rig if it has none): the moving
/// caster of the stability suite's motion probe and of `--synthetic town-mover`.
pub fn add_mover(
    scene: &mut Scene,
    name: &str,
    primitive: super::Primitive,
    material: super::Material,
    keys: &[(f32, Vec3)],
) {
    let mut rig = scene.rig.as_deref().cloned().unwrap_or_default();
    let node = rig.nodes.len();
    let start = keys.first().map_or(Vec3::ZERO, |k| k.1);
    rig.nodes.push(RigNode {
        parent: None,
        local: Local {
            matrix: Mat4::from_translation(start),
            translation: start,
            rotation: Quat::IDENTITY,
            scale: Vec3::ONE,
        },
        skin: None,
        weights: Vec::new(),
    });
    rig.animations.push(Animation {
        name: "move".into(),
        channels: vec![Channel {
            node,
            property: Property::Translation,
            keys: Keyframes {
                interpolation: Interpolation::Linear,
                times: keys.iter().map(|k| k.0).collect(),
                values: keys.iter().flat_map(|k| k.1.to_array()).collect(),
                width: 3,
            },
        }],
    });
    scene.node_names.resize(node, String::new());
    scene.node_names.push(name.into());
    super::built::shapes::add_object(
        scene,
        name,
        primitive,
        material,
        Mat4::from_translation(start),
    );
    if let Some(i) = scene.instances.last_mut() {
        i.node = Some(node);
    }
    scene.rig = Some(std::sync::Arc::new(rig));
}

#[cfg(test)]
mod tests {
    use super::*;

    fn node(parent: Option<usize>, t: Vec3) -> RigNode {
        RigNode {
            parent,
            local: Local {
                matrix: Mat4::from_translation(t),
                translation: t,
                rotation: Quat::IDENTITY,
                scale: Vec3::ONE,
            },
            skin: None,
            weights: Vec::new(),
        }
    }

    fn linear(node: usize, property: Property, times: &[f32], values: &[f32]) -> Channel {
        let width = match property {
            Property::Rotation => 4,
            Property::Weights => 2,
            _ => 3,
        };
        Channel {
            node,
            property,
            keys: Keyframes {
                interpolation: Interpolation::Linear,
                times: times.to_vec(),
                values: values.to_vec(),
                width,
            },
        }
    }

    #[test]
    fn a_hierarchy_poses_children_under_animated_parents() {
        // Root at the origin rotating about Y from 0° to 180° over 2 s; child 1 unit along +X.
        let mut rig = Rig {
            nodes: vec![node(None, Vec3::ZERO), node(Some(0), Vec3::X)],
            ..Default::default()
        };
        let q0 = Quat::IDENTITY;
        let q1 = Quat::from_rotation_y(90f32.to_radians());
        let q2 = Quat::from_rotation_y(180f32.to_radians());
        let mut ch = linear(0, Property::Rotation, &[0.0, 1.0, 2.0], &[]);
        ch.keys.values = [q0, q1, q2].iter().flat_map(|q| q.to_array()).collect();
        rig.animations.push(Animation {
            name: "spin".into(),
            channels: vec![
                ch,
                linear(
                    1,
                    Property::Translation,
                    &[0.0, 2.0],
                    &[1.0, 0.0, 0.0, 3.0, 0.0, 0.0],
                ),
            ],
        });
        assert_eq!(rig.duration(&Playing::One(0)), 2.0);
        // At t = 1: root turned 90° about Y (X → -Z), child translated to x = 2 → (0, 0, -2).
        let p = rig.pose(&Playing::One(0), 1.0);
        let c = p.world[1].transform_point3(Vec3::ZERO);
        assert!(c.abs_diff_eq(Vec3::new(0.0, 0.0, -2.0), 1e-5), "{c}");
        // At rest, the file's transforms.
        let p = rig.pose(&Playing::Rest, 1.0);
        assert_eq!(p.world[1], Mat4::from_translation(Vec3::X));
        // Past the end, clamped: 180°, child at x = 3 → (-3, 0, 0).
        let p = rig.pose(&Playing::All, 10.0);
        let c = p.world[1].transform_point3(Vec3::ZERO);
        assert!(c.abs_diff_eq(Vec3::new(-3.0, 0.0, 0.0), 1e-5), "{c}");
    }

    #[test]
    fn joint_matrices_combine_world_and_inverse_bind() {
        let mut rig = Rig {
            nodes: vec![node(None, Vec3::new(0.0, 2.0, 0.0))],
            ..Default::default()
        };
        rig.skins.push(Skin {
            name: String::new(),
            joints: vec![0],
            inverse_bind: vec![Mat4::from_translation(Vec3::new(0.0, -2.0, 0.0))],
        });
        // At rest world · inverse bind is identity: the bind pose.
        let p = rig.pose(&Playing::Rest, 0.0);
        assert_eq!(p.joints[0][0], Mat4::IDENTITY);
        // Weights animate, and the node's default stays where nothing animates them.
        rig.nodes[0].weights = vec![0.25, 0.0];
        rig.animations.push(Animation {
            name: "w".into(),
            channels: vec![linear(
                0,
                Property::Weights,
                &[0.0, 1.0],
                &[0.0, 0.0, 1.0, 0.5],
            )],
        });
        assert_eq!(rig.pose(&Playing::Rest, 0.5).weights[0], vec![0.25, 0.0]);
        assert_eq!(rig.pose(&Playing::One(0), 0.5).weights[0], vec![0.5, 0.25]);
    }

    #[test]
    fn playing_parses_indices_names_and_all() {
        let rig = Rig {
            animations: vec![
                Animation {
                    name: "Walk".into(),
                    channels: vec![],
                },
                Animation {
                    name: "Run".into(),
                    channels: vec![],
                },
            ],
            ..Default::default()
        };
        assert_eq!(Playing::parse("1", Some(&rig)), Ok(Playing::One(1)));
        assert_eq!(Playing::parse("Walk", Some(&rig)), Ok(Playing::One(0)));
        assert_eq!(Playing::parse("all", Some(&rig)), Ok(Playing::All));
        let e = Playing::parse("2", Some(&rig)).unwrap_err();
        assert!(e.contains("0 'Walk', 1 'Run'"), "{e}");
        let e = Playing::parse("Jump", None).unwrap_err();
        assert!(e.contains("no animations"), "{e}");
    }
}
