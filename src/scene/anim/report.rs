//! The motion part of `umbra inspect`: animations (duration, channels by path and
//! interpolation, target nodes), skins (joints, inverse bind matrices, most influences on a
//! vertex) and morph targets (count, attributes, default weights).

use super::Rig;
use crate::scene::Scene;
use serde_json::{json, Value};

/// The `motion` section: empty lists for a file that does not move.
pub fn motion_report(doc: &Value, scene: &Scene) -> Value {
    let rig = scene.rig.as_deref();
    let empty = Rig::default();
    let rig = rig.unwrap_or(&empty);
    let names = &scene.node_names;
    let name = |n: usize| names.get(n).cloned().unwrap_or_default();
    let animations: Vec<Value> = rig
        .animations
        .iter()
        .enumerate()
        .map(|(i, a)| {
            let channels: Vec<Value> = a
                .channels
                .iter()
                .map(|c| {
                    json!({"node": c.node, "node_name": name(c.node), "path": c.property.name(),
                           "interpolation": c.keys.interpolation.name(),
                           "keyframes": c.keys.times.len(),
                           "start": c.keys.range().0, "end": c.keys.range().1})
                })
                .collect();
            let mut targets: Vec<usize> = a.channels.iter().map(|c| c.node).collect();
            targets.sort_unstable();
            targets.dedup();
            let declared = doc["animations"][i]["channels"]
                .as_array()
                .map_or(0, |c| c.len());
            json!({"index": i, "name": a.name, "duration": a.duration(),
                   "channels": channels, "channels_ignored": declared - a.channels.len(),
                   "target_nodes": targets})
        })
        .collect();
    let skins: Vec<Value> = rig
        .skins
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let bound: Vec<usize> = (0..rig.nodes.len())
                .filter(|&n| rig.nodes[n].skin == Some(i))
                .collect();
            json!({"index": i, "name": s.name, "joints": s.joints.len(),
                   "inverse_bind_matrices": doc["skins"][i].get("inverseBindMatrices").is_some(),
                   "max_influences": max_influences(scene, &bound),
                   "nodes": bound})
        })
        .collect();
    let mut morphs = Vec::new();
    for (mi, m) in arr(doc, "meshes").iter().enumerate() {
        for (pi, p) in arr(m, "primitives").iter().enumerate() {
            let targets = arr(p, "targets");
            if targets.is_empty() {
                continue;
            }
            let mut attributes: Vec<&str> = targets
                .iter()
                .flat_map(|t| t.as_object().into_iter().flat_map(|o| o.keys()))
                .map(|k| k.as_str())
                .collect();
            attributes.sort_unstable();
            attributes.dedup();
            morphs.push(
                json!({"mesh": mi, "primitive": pi, "targets": targets.len(),
                               "attributes": attributes, "default_weights": m["weights"]}),
            );
        }
    }
    json!({"animations": animations, "skins": skins, "morph_targets": morphs})
}

fn arr<'a>(v: &'a Value, key: &str) -> &'a [Value] {
    v[key].as_array().map_or(&[], |a| &a[..])
}

/// The most joints with non-zero weight on one vertex, over the primitives drawn by `nodes`.
fn max_influences(scene: &Scene, nodes: &[usize]) -> usize {
    scene
        .instances
        .iter()
        .filter(|i| i.node.is_some_and(|n| nodes.contains(&n)))
        .flat_map(|i| &scene.meshes[i.mesh].primitives)
        .filter_map(|p| p.deform.as_deref().filter(|d| d.skinned()))
        .flat_map(|d| {
            d.weights
                .chunks(d.sets)
                .map(|run| run.iter().flatten().filter(|w| **w > 0.0).count())
        })
        .max()
        .unwrap_or(0)
}
