use super::*;
use crate::scene::mesh::topology::is_closed;

#[test]
fn every_listed_name_builds_a_scene() {
    for name in NAMES {
        assert!(by_name(name).is_some(), "{name}");
    }
    assert!(by_name("spheres:3").is_some() && by_name("spheres:257").is_none());
}

#[test]
fn double_sided_scene_is_sized_like_the_sample() {
    let s = double_sided_scene();
    assert_eq!(s.instances.len(), 12);
    let tris = s.triangle_count();
    assert!((50_000..60_000).contains(&tris), "{tris} triangles");
    assert!(s.materials.iter().all(|m| m.double_sided));
    let closed = s
        .meshes
        .iter()
        .filter(|m| is_closed(&m.primitives[0].positions, &m.primitives[0].indices))
        .count();
    assert_eq!(closed, 11, "the spheres are closed, the ground is not");
    assert_eq!(sphere_grid(4).instances.len(), 17);
}

#[test]
fn close_up_scene_is_open_and_sized_like_the_sample() {
    let s = close_up_scene();
    assert_eq!(s.instances.len(), 12);
    assert_eq!(s.triangle_count(), 50_690);
    assert!(s.materials.iter().all(|m| m.double_sided));
    assert!(s
        .meshes
        .iter()
        .all(|m| !is_closed(&m.primitives[0].positions, &m.primitives[0].indices)));
    // Nothing sinks below the ground (so, as in the sample, the ground shadows nothing).
    assert!(s.bounds().min.y >= -1e-6, "{:?}", s.bounds());
}
