//! What a loaded file says about motion: nodes, skins, channels, animations; [`Rig::pose`]
//! evaluates it at a time into a [`Pose`]. Plain data and maths: no scene.

use super::sample::Keyframes;
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
