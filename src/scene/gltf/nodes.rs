//! The glTF node hierarchy walked into instances, cameras and lights, with what animation needs
//! from it (each node's parent, the nodes lights and cameras hang on).

use super::error::{corrupt, LoadError};
use crate::scene::{Camera, Instance, Light, LightKind, Projection, Scene};
use glam::{Mat4, Vec3};
use std::path::Path;

/// What animation needs from the walk.
pub(super) struct Walk {
    /// Each node's parent.
    pub parents: Vec<Option<usize>>,
    /// The node of each light, in `scene.lights` order.
    pub light_nodes: Vec<usize>,
    /// The node of each camera, in `scene.cameras` order.
    pub camera_nodes: Vec<usize>,
}

/// Walks the default scene's nodes (or every root), adding instances, cameras and lights at their
/// world transforms.
pub(super) fn walk_nodes(
    path: &Path,
    gltf: &gltf::Gltf,
    scene: &mut Scene,
) -> Result<Walk, LoadError> {
    scene.node_names = gltf
        .nodes()
        .map(|n| n.name().unwrap_or_default().to_string())
        .collect();
    let roots: Vec<gltf::Node> = match gltf.default_scene().or_else(|| gltf.scenes().next()) {
        Some(s) => s.nodes().collect(),
        None => {
            let mut is_child = vec![false; gltf.nodes().len()];
            for n in gltf.nodes() {
                for c in n.children() {
                    is_child[c.index()] = true;
                }
            }
            gltf.nodes().filter(|n| !is_child[n.index()]).collect()
        }
    };
    let mut stack: Vec<(gltf::Node, Mat4, usize)> =
        roots.into_iter().map(|n| (n, Mat4::IDENTITY, 0)).collect();
    let mut visited = 0usize;
    // What motion needs from the walk: each node's parent, and the nodes lights and cameras
    // hang on.
    let mut parents: Vec<Option<usize>> = vec![None; gltf.nodes().len()];
    let (mut light_nodes, mut camera_nodes) = (Vec::new(), Vec::<usize>::new());
    while let Some((node, parent, depth)) = stack.pop() {
        visited += 1;
        if depth > 256 || visited > 1_000_000 {
            return Err(corrupt(path, "node hierarchy too deep or cyclic".into()));
        }
        let local = Mat4::from_cols_array_2d(&node.transform().matrix());
        let world = parent * local;
        if !world.is_finite() {
            scene.warn(
                "NODE_NONFINITE_TRANSFORM",
                format!("/nodes/{}", node.index()),
                format!("node {} has a non-finite transform; skipped", node.index()),
            );
            continue;
        }
        if let Some(m) = node.mesh() {
            scene.instances.push(Instance {
                mesh: m.index(),
                world_from_model: world,
                node: Some(node.index()),
            });
        }
        if let Some(c) = node.camera() {
            add_camera(scene, &c, world);
            camera_nodes.push(node.index());
        }
        if let Some(l) = node.light() {
            light_nodes.push(node.index());
            add_light(scene, &l, world);
        }
        for c in node.children() {
            parents[c.index()] = Some(node.index());
            stack.push((c, world, depth + 1));
        }
    }
    // Cameras in the document's node order, not the walk's (`--camera N` and the viewer's `C`
    // count them so).
    let mut order: Vec<usize> = (0..camera_nodes.len()).collect();
    order.sort_by_key(|&k| camera_nodes[k]);
    let first = scene.cameras.len() - camera_nodes.len();
    let sorted: Vec<_> = order.iter().map(|&k| scene.cameras[first + k]).collect();
    scene.cameras.truncate(first);
    scene.cameras.extend(sorted);
    let camera_nodes = order.iter().map(|&k| camera_nodes[k]).collect();
    Ok(Walk {
        parents,
        light_nodes,
        camera_nodes,
    })
}

/// Adds camera `c` at `world` (scale removed), perspective or orthographic; parameters out of
/// range are repaired with a `CAMERA_INVALID` warning.
fn add_camera(scene: &mut Scene, c: &gltf::Camera, world: Mat4) {
    let (_, rot, pos) = world.to_scale_rotation_translation();
    let world_from_view = Mat4::from_rotation_translation(rot, pos);
    let pointer = format!("/cameras/{}", c.index());
    let mut repairs = Vec::new();
    let camera = match c.projection() {
        gltf::camera::Projection::Perspective(p) => Camera {
            world_from_view,
            projection: Projection::Perspective {
                fov_y: p.yfov().clamp(0.01, 3.1),
            },
            near: p.znear().max(1e-6),
            far: p.zfar(),
        },
        gltf::camera::Projection::Orthographic(o) => {
            let mag = |m: f32, name: &str, repairs: &mut Vec<String>| {
                if m.is_finite() && m != 0.0 {
                    m.abs()
                } else {
                    repairs.push(format!("{name} {m} read as 1"));
                    1.0
                }
            };
            let (xmag, ymag) = (
                mag(o.xmag(), "xmag", &mut repairs),
                mag(o.ymag(), "ymag", &mut repairs),
            );
            let near = if o.znear().is_finite() {
                o.znear().max(0.0)
            } else {
                0.0
            };
            let far = Some(o.zfar()).filter(|f| f.is_finite() && *f > near);
            if far.is_none() {
                repairs.push(format!(
                    "zfar {} is not beyond znear {near}: seen {} units deep",
                    o.zfar(),
                    Camera::ORTHO_DEFAULT_DEPTH * ymag
                ));
            }
            Camera {
                world_from_view,
                projection: Projection::Orthographic { xmag, ymag },
                near,
                far,
            }
        }
    };
    if !repairs.is_empty() {
        scene.warn(
            "CAMERA_INVALID",
            pointer,
            format!("camera {}: {}", c.index(), repairs.join("; ")),
        );
    }
    scene.cameras.push(camera);
}

/// Adds light `l` at `world`: position, the direction it shines (its −Z), and the size an
/// `extras.light_size` gives it.
fn add_light(scene: &mut Scene, l: &gltf::khr_lights_punctual::Light, world: Mat4) {
    let (_, rot, pos) = world.to_scale_rotation_translation();
    let dir = (rot * -Vec3::Z).normalize_or_zero();
    let kind = match l.kind() {
        gltf::khr_lights_punctual::Kind::Directional => LightKind::Directional,
        gltf::khr_lights_punctual::Kind::Point => LightKind::Point,
        gltf::khr_lights_punctual::Kind::Spot {
            inner_cone_angle,
            outer_cone_angle,
        } => LightKind::Spot {
            inner: inner_cone_angle,
            outer: outer_cone_angle.max(inner_cone_angle + 1e-4),
        },
    };
    let size = light_size_extra(l.extras().as_deref().map(|r| r.get())).unwrap_or_else(|e| {
        scene.warn(
            "LIGHT_SIZE_INVALID",
            format!(
                "/extensions/KHR_lights_punctual/lights/{}/extras",
                l.index()
            ),
            format!("light {}: {e}; the light casts hard shadows", l.index()),
        );
        0.0
    });
    scene.lights.push(Light {
        kind,
        position: pos,
        direction: dir,
        color: Vec3::from_array(l.color()),
        intensity: l.intensity().max(0.0),
        casts_shadows: true,
        range: l.range().filter(|r| r.is_finite() && *r > 0.0),
        size: if kind == LightKind::Directional {
            size.to_radians()
        } else {
            size
        },
    });
}

/// The emitter size in a glTF light's `extras` (`{"light_size": S}`: degrees of angular
/// diameter for a directional light, scene units of radius otherwise); 0 without one.
pub(super) fn light_size_extra(extras: Option<&str>) -> Result<f32, String> {
    let Some(json) = extras else {
        return Ok(0.0);
    };
    let v: serde_json::Value =
        serde_json::from_str(json).map_err(|e| format!("extras are not JSON: {e}"))?;
    match v.get("light_size") {
        None => Ok(0.0),
        Some(s) => match s.as_f64() {
            Some(x) if x.is_finite() && (0.0..=1e6).contains(&x) => Ok(x as f32),
            _ => Err(format!("extras.light_size {s} is not a number in 0..1e6")),
        },
    }
}
