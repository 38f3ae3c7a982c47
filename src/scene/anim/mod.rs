//! Scenes that move: glTF node animation (translation, rotation, scale, morph weights), skins
//! and morph targets. [`Rig`] holds what a loaded file says about motion; [`Rig::pose`] evaluates
//! it at a time into a [`Pose`] (node world matrices, joint matrices, morph weights), and
//! [`Scene::apply_pose`] writes that pose into the scene's instances, lights, cameras and
//! deformed vertices, so the GPU path, the ray-cast reference, `inspect` and picking all see the
//! same posed scene.

mod deform;
pub mod load;
pub mod report;
mod sample;

pub use deform::{deform, Deform, MorphTarget, Posed};
pub use sample::{hermite, slerp, Interpolation, Keyframes};

use super::{Camera, Scene};
use glam::{Mat4, Quat, Vec3};

/// A node's local transform as the file gives it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Local {
    /// The local matrix (the file's matrix, or its TRS composed), used where nothing animates.
    pub matrix: Mat4,
    /// Translation (the matrix decomposed when the file gives a matrix).
    pub translation: Vec3,
    /// Rotation.
    pub rotation: Quat,
    /// Scale.
    pub scale: Vec3,
}

/// One glTF node, as far as motion needs it.
#[derive(Clone, Debug, PartialEq)]
pub struct RigNode {
    /// Parent node (the first one found; a node with two is refused by the loader's walk).
    pub parent: Option<usize>,
    /// Rest transform.
    pub local: Local,
    /// The skin its mesh is bound to.
    pub skin: Option<usize>,
    /// Default morph weights: the node's `weights`, else its mesh's; empty without targets.
    pub weights: Vec<f32>,
}

/// A skin: the nodes acting as joints and their inverse bind matrices.
#[derive(Clone, Debug, PartialEq)]
pub struct Skin {
    /// Name from the file.
    pub name: String,
    /// Joint node indices.
    pub joints: Vec<usize>,
    /// One per joint (identity where the file gives none).
    pub inverse_bind: Vec<Mat4>,
}

/// What a channel animates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Property {
    /// Node translation.
    Translation,
    /// Node rotation.
    Rotation,
    /// Node scale.
    Scale,
    /// Morph target weights of the node's mesh.
    Weights,
}

impl Property {
    /// The glTF path name.
    pub fn name(self) -> &'static str {
        match self {
            Property::Translation => "translation",
            Property::Rotation => "rotation",
            Property::Scale => "scale",
            Property::Weights => "weights",
        }
    }
}

/// One animated property of one node.
#[derive(Clone, Debug, PartialEq)]
pub struct Channel {
    /// Target node.
    pub node: usize,
    /// Target property.
    pub property: Property,
    /// Its keyframes.
    pub keys: Keyframes,
}

/// A glTF animation: channels played together.
#[derive(Clone, Debug, PartialEq)]
pub struct Animation {
    /// Name from the file (empty where it has none).
    pub name: String,
    /// Its valid channels (the loader warns about and drops the others).
    pub channels: Vec<Channel>,
}

impl Animation {
    /// The last keyframe time of any channel (0 without channels).
    pub fn duration(&self) -> f32 {
        self.channels
            .iter()
            .map(|c| c.keys.range().1)
            .fold(0.0, f32::max)
    }
}

/// Which animations play.
#[derive(Clone, Debug, PartialEq, Eq, Default)]
pub enum Playing {
    /// None: the rest pose (the file's node transforms, default morph weights, skins applied).
    #[default]
    Rest,
    /// One animation, by index.
    One(usize),
    /// Every animation, in file order (a later one's channel wins on the same property).
    All,
}

impl Playing {
    /// What plays when nothing is chosen: the first animation, or the rest pose without one.
    pub fn first(rig: Option<&Rig>) -> Self {
        match rig {
            Some(r) if !r.animations.is_empty() => Playing::One(0),
            _ => Playing::Rest,
        }
    }

    /// Parses `--animation`: an index, a name, or `all`; the error names the choices.
    pub fn parse(spec: &str, rig: Option<&Rig>) -> Result<Self, String> {
        let anims = rig.map_or(&[][..], |r| &r.animations[..]);
        let names = || {
            let list: Vec<String> = anims
                .iter()
                .enumerate()
                .map(|(i, a)| format!("{i} '{}'", a.name))
                .collect();
            if list.is_empty() {
                "the scene has no animations".to_string()
            } else {
                format!("the scene has {}", list.join(", "))
            }
        };
        if spec == "all" {
            return Ok(Playing::All);
        }
        if let Ok(i) = spec.parse::<usize>() {
            return if i < anims.len() {
                Ok(Playing::One(i))
            } else {
                Err(format!("--animation {i}: {}", names()))
            };
        }
        anims
            .iter()
            .position(|a| a.name == spec)
            .map(Playing::One)
            .ok_or_else(|| format!("--animation '{spec}': {}", names()))
    }
}

/// Motion data of a loaded scene.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Rig {
    /// Every glTF node.
    pub nodes: Vec<RigNode>,
    /// Skins.
    pub skins: Vec<Skin>,
    /// Animations.
    pub animations: Vec<Animation>,
    /// The node each of the scene's lights hangs on (index-aligned with `Scene::lights`).
    pub light_nodes: Vec<usize>,
    /// The node each of the scene's cameras hangs on (index-aligned with `Scene::cameras`).
    pub camera_nodes: Vec<usize>,
}

/// A scene's pose at one time.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Pose {
    /// World matrix of every node.
    pub world: Vec<Mat4>,
    /// Per skin, per joint: world_from_joint · inverse bind matrix.
    pub joints: Vec<Vec<Mat4>>,
    /// Morph weights of every node (empty where its mesh has no targets).
    pub weights: Vec<Vec<f32>>,
}

impl Rig {
    /// Duration of what `playing` plays, seconds (0 for the rest pose).
    pub fn duration(&self, playing: &Playing) -> f32 {
        match playing {
            Playing::Rest => 0.0,
            Playing::One(i) => self.animations.get(*i).map_or(0.0, Animation::duration),
            Playing::All => self
                .animations
                .iter()
                .map(Animation::duration)
                .fold(0.0, f32::max),
        }
    }

    /// The pose at time `t` seconds of `playing` (each channel's time clamped to its keyframes,
    /// as the spec says; a player that loops wraps `t` itself).
    pub fn pose(&self, playing: &Playing, t: f32) -> Pose {
        let n = self.nodes.len();
        let mut trs: Vec<Option<(Vec3, Quat, Vec3)>> = vec![None; n];
        let mut weights: Vec<Vec<f32>> = self.nodes.iter().map(|d| d.weights.clone()).collect();
        let chosen: Vec<&Animation> = match playing {
            Playing::Rest => Vec::new(),
            Playing::One(i) => self.animations.get(*i).into_iter().collect(),
            Playing::All => self.animations.iter().collect(),
        };
        for c in chosen.iter().flat_map(|a| &a.channels) {
            let Some(node) = self.nodes.get(c.node) else {
                continue;
            };
            let l = node.local;
            let v = trs[c.node].get_or_insert((l.translation, l.rotation, l.scale));
            match c.property {
                Property::Translation => v.0 = sample3(&c.keys, t),
                Property::Rotation => v.1 = c.keys.sample_rotation(t),
                Property::Scale => v.2 = sample3(&c.keys, t),
                Property::Weights => {
                    let w = &mut weights[c.node];
                    w.resize(c.keys.width.max(w.len()), 0.0);
                    c.keys.sample_into(t, &mut w[..c.keys.width]);
                }
            }
        }
        let local: Vec<Mat4> = (0..n)
            .map(|i| match trs[i] {
                Some((t, r, s)) => Mat4::from_scale_rotation_translation(s, r, t),
                None => self.nodes[i].local.matrix,
            })
            .collect();
        let world = self.worlds(&local);
        let joints = self
            .skins
            .iter()
            .map(|s| {
                s.joints
                    .iter()
                    .zip(&s.inverse_bind)
                    .map(|(&j, ibm)| world.get(j).copied().unwrap_or(Mat4::IDENTITY) * *ibm)
                    .collect()
            })
            .collect();
        Pose {
            world,
            joints,
            weights,
        }
    }

    /// World matrices from local ones through the parent links: a root's is identity · local,
    /// as the loader's walk computes it. Parent links form no cycle (the loader checks).
    fn worlds(&self, local: &[Mat4]) -> Vec<Mat4> {
        let n = self.nodes.len();
        let mut world: Vec<Option<Mat4>> = vec![None; n];
        for start in 0..n {
            // Walk up to the first node with a known world (or a root), then back down.
            let mut chain = vec![start];
            while let Some(p) = self.nodes[*chain.last().unwrap_or(&start)].parent {
                if world[p].is_some() || chain.len() > n {
                    break;
                }
                chain.push(p);
            }
            for &i in chain.iter().rev() {
                if world[i].is_some() {
                    continue;
                }
                let parent = self.nodes[i]
                    .parent
                    .and_then(|p| world[p])
                    .unwrap_or(Mat4::IDENTITY);
                world[i] = Some(parent * local[i]);
            }
        }
        world
            .into_iter()
            .map(|w| w.unwrap_or(Mat4::IDENTITY))
            .collect()
    }
}

fn sample3(k: &Keyframes, t: f32) -> Vec3 {
    let mut v = [0.0; 3];
    if k.width == 3 {
        k.sample_into(t, &mut v);
    }
    Vec3::from_array(v)
}

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
    super::shapes::add_object(
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
