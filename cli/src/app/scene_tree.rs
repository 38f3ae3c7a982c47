//! The glTF scene tree the panel shows, from `umbra inspect`'s report, and the world bounds of a
//! node with everything under it (what selecting it frames).

use serde_json::Value;
use umbra::math::Aabb;
use umbra::scene::Scene;

/// One node of the tree.
#[derive(Clone, Debug, PartialEq)]
pub struct TreeNode {
    /// Its name ("" when it has none).
    pub name: String,
    /// Its children, by node index.
    pub children: Vec<usize>,
    /// The mesh it places, if any.
    pub mesh: Option<usize>,
    /// Whether it holds a camera or a light.
    pub camera: bool,
    /// Whether it holds a light.
    pub light: bool,
}

impl TreeNode {
    /// The line the panel shows for node `i`.
    pub fn label(&self, i: usize) -> String {
        let mut s = format!("{i}");
        if !self.name.is_empty() {
            s += &format!(" {}", self.name);
        }
        if let Some(m) = self.mesh {
            s += &format!(" · mesh {m}");
        }
        if self.camera {
            s += " · camera";
        }
        if self.light {
            s += " · light";
        }
        s
    }
}

/// The nodes of the scene shown and its roots.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SceneTree {
    /// Every node of the document, by index.
    pub nodes: Vec<TreeNode>,
    /// The roots of the scene shown.
    pub roots: Vec<usize>,
}

impl SceneTree {
    /// The tree of an inspect report (`umbra::scene::inspect::document_report`).
    pub fn from_report(report: &Value) -> Self {
        let st = &report["scene_tree"];
        let index = |v: &Value| v.as_u64().map(|i| i as usize);
        let nodes = st["nodes"]
            .as_array()
            .map(|a| {
                a.iter()
                    .map(|n| TreeNode {
                        name: n["name"].as_str().unwrap_or("").to_string(),
                        children: n["children"]
                            .as_array()
                            .map(|c| c.iter().filter_map(index).collect())
                            .unwrap_or_default(),
                        mesh: index(&n["mesh"]),
                        camera: !n["camera"].is_null(),
                        light: !n["light"].is_null(),
                    })
                    .collect()
            })
            .unwrap_or_default();
        let roots = st["roots"]
            .as_array()
            .map(|a| a.iter().filter_map(index).collect())
            .unwrap_or_default();
        Self { nodes, roots }
    }

    /// Node `i` and every node under it (each once, whatever the document's links).
    pub fn subtree(&self, i: usize) -> Vec<usize> {
        let mut seen = vec![false; self.nodes.len()];
        let mut out = Vec::new();
        let mut stack = vec![i];
        while let Some(n) = stack.pop() {
            if n >= self.nodes.len() || seen[n] {
                continue;
            }
            seen[n] = true;
            out.push(n);
            stack.extend(self.nodes[n].children.iter().copied());
        }
        out
    }

    /// The world bounds of what node `i` and its descendants place in `scene`, and the first
    /// (instance, primitive) among them (to tint); None when they place nothing.
    pub fn bounds(&self, i: usize, scene: &Scene) -> Option<(Aabb, (usize, usize))> {
        let under = self.subtree(i);
        let mut b = Aabb::EMPTY;
        let mut first = None;
        for (k, inst) in scene.instances.iter().enumerate() {
            if inst.node.is_some_and(|n| under.contains(&n)) {
                for p in &scene.meshes[inst.mesh].primitives {
                    b = b.union(&p.bounds().transformed(&inst.world_from_model));
                }
                first.get_or_insert((k, 0));
            }
        }
        first.filter(|_| !b.is_empty()).map(|f| (b, f))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn the_tree_reads_the_report_and_walks_each_node_once() {
        let report = json!({"scene_tree": {"roots": [0, 3], "nodes": [
            {"index": 0, "name": "root", "children": [1, 2]},
            {"index": 1, "name": "", "mesh": 0, "children": [2]},
            {"index": 2, "name": "lamp", "light": 0},
            {"index": 3, "name": "eye", "camera": 1},
        ]}});
        let t = SceneTree::from_report(&report);
        assert_eq!(t.roots, [0, 3]);
        assert_eq!(t.nodes[1].label(1), "1 · mesh 0");
        assert_eq!(t.nodes[2].label(2), "2 lamp · light");
        assert_eq!(t.nodes[3].label(3), "3 eye · camera");
        let mut under = t.subtree(0);
        under.sort();
        assert_eq!(under, [0, 1, 2], "node 2 is reached twice, listed once");
        assert_eq!(t.subtree(9), Vec::<usize>::new());
    }
}
