//! Generated benchmark scenes: a double-sided scene shaped like the C++ Vulkan sample's
//! (about 52k triangles in 12 primitives, every material double-sided), grids of spheres for
//! frame time against triangle count, a town for shadows at every distance, and scenes where
//! several lights cast (a point light in a room, a sun with a spot lamp, two suns).

use crate::scene::built::shapes::{add_object, colored, cuboid, plane, torus, uv_sphere};
use crate::scene::{Camera, Light, LightKind, Scene};
use glam::{Mat4, Vec3};

/// A colour material of `roughness` marked double-sided.
fn two_sided(rgb: Vec3, roughness: f32) -> crate::scene::Material {
    let mut m = colored(rgb, roughness);
    m.double_sided = true;
    m
}

/// A scene named `name` holding a grey double-sided ground 30 units across.
fn on_double_sided_ground(name: &str, roughness: f32) -> Scene {
    let mut s = Scene {
        name: name.into(),
        ..Default::default()
    };
    add_object(
        &mut s,
        "ground",
        plane(30.0, 1.0),
        two_sided(Vec3::splat(0.5), roughness),
        Mat4::IDENTITY,
    );
    s
}

/// A ground plane and 11 spheres of 4,736 triangles (52,098 triangles, 12 primitives), every
/// material double-sided (as exporters often mark them); the spheres are closed meshes, the
/// ground is open. One sun at about 40° elevation, one camera.
pub fn double_sided_scene() -> Scene {
    let mut s = on_double_sided_ground("double-sided", 0.5);
    let two = |rgb: Vec3| two_sided(rgb, 0.5);
    for i in 0..11 {
        let a = i as f32 / 11.0 * std::f32::consts::TAU;
        let r = if i % 2 == 0 { 5.0 } else { 8.0 };
        let radius = 0.8 + 0.3 * (i % 3) as f32;
        let hue = Vec3::new(
            0.3 + 0.6 * (a.cos() * 0.5 + 0.5),
            0.4,
            0.3 + 0.6 * (a.sin() * 0.5 + 0.5),
        );
        add_object(
            &mut s,
            &format!("sphere {i}"),
            uv_sphere(radius, 64, 38),
            two(hue),
            Mat4::from_translation(Vec3::new(r * a.cos(), radius, r * a.sin())),
        );
    }
    s.lights.push(Light::sun(Vec3::new(-0.6, -1.0, -0.4), 2.0));
    s.cameras.push(Camera::look_at(
        Vec3::new(0.0, 9.0, 17.0),
        Vec3::new(0.0, 0.0, 0.0),
        50f32.to_radians(),
        0.1,
    ));
    s
}

/// The stand-in for the C++ sample's scene at its own camera: a ground and 11 open, organic,
/// double-sided models of 4,608 triangles each (vases, leaves, shells, ribbons: 50,690
/// triangles, 12 primitives) seen from close by with a 60° lens, so that the models cover about
/// a third of the frame and both faces of most of them are drawn. One sun about 40° high.
pub fn close_up_scene() -> Scene {
    use crate::scene::built::open_shapes::{leaf, ribbon, shell, vase};
    let mut s = on_double_sided_ground("close-up", 0.45);
    let two = |rgb: Vec3| two_sided(rgb, 0.45);
    let models = [
        ("vase", vase(0.9, 2.2, 5.0, 64, 36)),
        ("leaf", leaf(2.4, 1.0, 0.9, 96, 24)),
        ("shell", shell(1.0, 2.2, 14.0, 64, 36)),
        ("ribbon", ribbon(1.1, 0.35, 4.6, 5.2, 128, 18)),
    ];
    for i in 0..11 {
        let a = i as f32 / 11.0 * std::f32::consts::TAU + 0.3;
        let r = if i % 2 == 0 { 1.7 } else { 3.4 };
        let (name, prim) = &models[i % 4];
        let hue = Vec3::new(
            0.3 + 0.6 * (a.cos() * 0.5 + 0.5),
            0.45,
            0.3 + 0.6 * (a.sin() * 0.5 + 0.5),
        );
        // Resting on the ground or above it, never sunk into it (as the sample's models stand).
        let lowest = prim
            .positions
            .iter()
            .map(|p| p.y)
            .fold(f32::INFINITY, f32::min);
        let lift = match *name {
            "leaf" => 1.0f32,
            "shell" | "ribbon" => 0.4,
            _ => 0.0,
        }
        .max(-lowest);
        let place = Mat4::from_translation(Vec3::new(r * a.cos(), lift, r * a.sin()))
            * Mat4::from_rotation_y(a * 1.7);
        add_object(
            &mut s,
            &format!("{name} {i}"),
            prim.clone(),
            two(hue),
            place,
        );
    }
    s.lights.push(Light::sun(Vec3::new(-0.6, -1.0, -0.4), 2.0));
    s.cameras.push(Camera::look_at(
        Vec3::new(0.0, 2.6, 5.4),
        Vec3::new(0.0, 0.7, 0.0),
        60f32.to_radians(),
        0.1,
    ));
    s
}

/// A ground plane and `n`×`n` spheres of radius 0.4 at spacing 1 (1,200 triangles each), the
/// layout of the pyrender peer's synthetic grid, seen from its camera direction under its sun.
pub fn sphere_grid(n: u32) -> Scene {
    let mut s = Scene {
        name: format!("spheres {n}x{n}"),
        ..Default::default()
    };
    let n = n.max(1);
    let half = (n - 1) as f32 * 0.5;
    let side = n as f32 + 2.0;
    add_object(
        &mut s,
        "ground",
        plane(side, 1.0),
        colored(Vec3::splat(0.6), 0.8),
        Mat4::IDENTITY,
    );
    let sphere = uv_sphere(0.4, 30, 21);
    for i in 0..n {
        for j in 0..n {
            add_object(
                &mut s,
                &format!("sphere {i},{j}"),
                sphere.clone(),
                colored(Vec3::new(0.7, 0.3 + 0.4 * (i % 2) as f32, 0.2), 0.5),
                Mat4::from_translation(Vec3::new(i as f32 - half, 0.55, j as f32 - half)),
            );
        }
    }
    s.lights.push(Light::sun(Vec3::new(0.9, -1.0, -0.25), 2.0));
    // The peer's view: from (0.55, 0.45, 1) at the distance that fits the bounding sphere.
    let (c, r) = s.bounds().bounding_sphere();
    let fov = 45f32.to_radians();
    let dist = crate::math::projection::framing_distance(r, fov, 16.0 / 9.0);
    s.cameras.push(Camera::look_at(
        c + Vec3::new(0.55, 0.45, 1.0).normalize() * dist,
        c,
        fov,
        (dist - r).max(dist * 1e-3) * 0.5,
    ));
    s
}

/// The town's sun: the direction its light travels.
pub fn town_sun() -> Vec3 {
    Vec3::new(0.7, -0.6, 0.35).normalize()
}

/// The town's boxes as (centre of the base, half extents): a bench-sized box 6 m in front of the
/// street camera, then twelve buildings from 60 m to 940 m away.
pub fn town_boxes() -> Vec<(Vec3, Vec3)> {
    let mut b = vec![(Vec3::new(-0.5, 0.0, -6.0), Vec3::new(1.0, 0.5, 0.4))];
    for i in 0..12 {
        let a = i as f32 * 0.52;
        let r = 60.0 + 80.0 * i as f32;
        b.push((
            Vec3::new(r * a.sin(), 0.0, -r * a.cos()),
            Vec3::new(8.0, 6.0 + i as f32, 8.0),
        ));
    }
    b
}

/// A town as large as the shadow methods must handle: a 2 km ground, twelve buildings out to a
/// kilometre and a bench 6 m from the camera, which stands at eye height (1.7 m) looking down the
/// street (camera 0); camera 1 looks from a roof 150 m down the street.
pub fn town_scene() -> Scene {
    let mut s = Scene {
        name: "town".into(),
        ..Default::default()
    };
    add_object(
        &mut s,
        "ground",
        plane(2000.0, 1.0),
        colored(Vec3::splat(0.8), 1.0),
        Mat4::IDENTITY,
    );
    for (i, (c, h)) in town_boxes().into_iter().enumerate() {
        add_object(
            &mut s,
            &format!("box {i}"),
            cuboid(h),
            colored(Vec3::new(0.7, 0.3, 0.2), 1.0),
            Mat4::from_translation(c + Vec3::Y * h.y),
        );
    }
    s.lights.push(Light::sun(town_sun(), 2.0));
    s.cameras.push(Camera::look_at(
        Vec3::new(0.0, 1.7, 0.0),
        Vec3::new(0.0, 0.0, -9.0),
        60f32.to_radians(),
        0.1,
    ));
    s.cameras.push(Camera::look_at(
        Vec3::new(-20.0, 30.0, 40.0),
        Vec3::new(60.0, 0.0, -200.0),
        60f32.to_radians(),
        0.1,
    ));
    s
}

/// The town with one moving caster: a person-sized box (0.5 × 1.8 × 0.3 m) walking across the
/// street in front of camera 0, from (−3, 0, −4) to (3, 0, −12) in 4 s and back by 8 s
/// (animation "move"): what shadow caching is measured on.
pub fn town_mover_scene() -> Scene {
    let mut s = town_scene();
    s.name = "town-mover".into();
    let walker = cuboid(Vec3::new(0.25, 0.9, 0.15));
    // The box's origin is its centre: lift it so it stands on the ground.
    let up = Vec3::Y * 0.9;
    crate::scene::anim::add_mover(
        &mut s,
        "walker",
        walker,
        colored(Vec3::new(0.2, 0.4, 0.8), 1.0),
        &[
            (0.0, Vec3::new(-3.0, 0.0, -4.0) + up),
            (4.0, Vec3::new(3.0, 0.0, -12.0) + up),
            (8.0, Vec3::new(-3.0, 0.0, -4.0) + up),
        ],
    );
    s
}

/// Long shadows under a low sun: a 60 m ground, two rows of thin posts, spheres and crates, lit
/// by a sun 6° above the horizon (shadows 10× longer than their casters, receivers at grazing
/// incidence: where acne, peter-panning and stretched texels show first). Camera 0 looks along
/// the shadows from 2 m up, camera 1 across them from 12 m up.
pub fn grazing_scene() -> Scene {
    let mut s = Scene {
        name: "grazing".into(),
        ..Default::default()
    };
    add_object(
        &mut s,
        "ground",
        plane(60.0, 1.0),
        colored(Vec3::splat(0.75), 1.0),
        Mat4::IDENTITY,
    );
    let post = cuboid(Vec3::new(0.08, 1.2, 0.08));
    for i in 0..10 {
        for side in [-1.0f32, 1.0] {
            add_object(
                &mut s,
                &format!("post {i}{}", if side < 0.0 { "l" } else { "r" }),
                post.clone(),
                colored(Vec3::new(0.35, 0.3, 0.25), 1.0),
                Mat4::from_translation(Vec3::new(side * 3.0, 1.2, 8.0 - 3.0 * i as f32)),
            );
        }
    }
    let ball = uv_sphere(0.6, 32, 20);
    for i in 0..4 {
        add_object(
            &mut s,
            &format!("sphere {i}"),
            ball.clone(),
            colored(Vec3::new(0.3, 0.45, 0.7), 0.4),
            Mat4::from_translation(Vec3::new(-8.0 + 5.0 * i as f32, 0.6, -4.0 + 2.0 * i as f32)),
        );
    }
    for i in 0..3 {
        let h = Vec3::new(0.7, 0.5 + 0.4 * i as f32, 0.5);
        add_object(
            &mut s,
            &format!("crate {i}"),
            cuboid(h),
            colored(Vec3::new(0.6, 0.45, 0.25), 0.8),
            Mat4::from_translation(Vec3::new(7.0, h.y, 4.0 - 6.0 * i as f32))
                * Mat4::from_rotation_y(0.4 * i as f32),
        );
    }
    s.lights.push(Light::sun(
        Light::sun_direction(6f32.to_radians(), 2.6),
        2.0,
    ));
    s.cameras.push(Camera::look_at(
        Vec3::new(1.0, 2.0, 16.0),
        Vec3::new(0.0, 0.0, -10.0),
        55f32.to_radians(),
        0.05,
    ));
    s.cameras.push(Camera::look_at(
        Vec3::new(-18.0, 12.0, 6.0),
        Vec3::new(2.0, 0.0, -4.0),
        50f32.to_radians(),
        0.1,
    ));
    s
}

/// Half extents of the stability scene's thin wall (standing on the ground at the origin, its
/// broad faces towards ±Z): where peter-panning shows first.
pub const STABILITY_WALL_HALF: Vec3 = Vec3::new(1.5, 1.0, 0.02);

/// The stability suite's built-in scene (`--builtin`): a 30 m ground, the thin wall
/// [`STABILITY_WALL_HALF`] at the origin, a 1 m box, two spheres (smooth, 48×32, and coarse,
/// 12×8) and a torus lying flat (curved receivers that shadow themselves), lit by a sun at 35°
/// on the wall's +Z side; one camera looking over the wall's shadow.
pub fn stability_scene() -> Scene {
    let mut s = Scene {
        name: "stability".into(),
        ..Default::default()
    };
    add_object(
        &mut s,
        "ground",
        plane(30.0, 1.0),
        colored(Vec3::splat(0.75), 1.0),
        Mat4::IDENTITY,
    );
    add_object(
        &mut s,
        "wall",
        cuboid(STABILITY_WALL_HALF),
        colored(Vec3::new(0.7, 0.3, 0.2), 1.0),
        Mat4::from_translation(Vec3::Y * STABILITY_WALL_HALF.y),
    );
    add_object(
        &mut s,
        "box",
        cuboid(Vec3::splat(0.5)),
        colored(Vec3::new(0.6, 0.45, 0.25), 0.8),
        Mat4::from_translation(Vec3::new(-3.5, 0.5, 2.0)) * Mat4::from_rotation_y(0.5),
    );
    for (i, (segments, rings, x)) in [(48u32, 32u32, 3.0f32), (12, 8, 4.5)]
        .into_iter()
        .enumerate()
    {
        add_object(
            &mut s,
            &format!("sphere {i}"),
            uv_sphere(0.7, segments, rings),
            colored(Vec3::new(0.3, 0.45, 0.7), 0.4),
            Mat4::from_translation(Vec3::new(x, 0.7, 1.5 - 3.0 * i as f32)),
        );
    }
    add_object(
        &mut s,
        "torus",
        torus(0.8, 0.3, 48, 24),
        colored(Vec3::new(0.5, 0.6, 0.3), 0.5),
        Mat4::from_translation(Vec3::new(-3.0, 0.3, -3.0)),
    );
    s.lights.push(Light::sun(
        Light::sun_direction(35f32.to_radians(), 0.0),
        2.0,
    ));
    s.cameras.push(Camera::look_at(
        Vec3::new(5.0, 6.0, -11.0),
        Vec3::new(0.0, 0.0, -1.5),
        55f32.to_radians(),
        0.05,
    ));
    s
}

/// A double-sided box of colour `rgb` with half extents `half` centred at `at`.
fn boxed(s: &mut Scene, name: &str, half: Vec3, at: Vec3, rgb: Vec3) {
    let mut m = colored(rgb, 0.8);
    m.double_sided = true;
    add_object(s, name, cuboid(half), m, Mat4::from_translation(at));
}

/// An 8 × 3 × 6 m room (a double-sided box seen from inside) with a table, a cabinet, a stool, a
/// coat stand, a wall shelf and a ceiling panel, lit by one point light in the middle: their
/// shadows fall on the floor, two walls and the ceiling, in four of the light's cube faces.
/// Camera 0 stands in a corner.
pub fn room_scene() -> Scene {
    let mut s = Scene {
        name: "room".into(),
        ..Default::default()
    };
    let (wall, wood) = (Vec3::splat(0.8), Vec3::new(0.6, 0.4, 0.25));
    boxed(
        &mut s,
        "room",
        Vec3::new(4.0, 1.5, 3.0),
        Vec3::Y * 1.5,
        wall,
    );
    boxed(
        &mut s,
        "table top",
        Vec3::new(0.8, 0.04, 0.5),
        Vec3::Y * 0.75,
        wood,
    );
    for (x, z) in [(-0.7, -0.4), (0.7, -0.4), (-0.7, 0.4), (0.7, 0.4)] {
        boxed(
            &mut s,
            "leg",
            Vec3::new(0.04, 0.355, 0.04),
            Vec3::new(x, 0.355, z),
            wood,
        );
    }
    let furniture = [
        (
            "cabinet",
            Vec3::new(0.4, 0.9, 0.3),
            Vec3::new(-1.5, 0.9, -2.0),
        ),
        ("stand", Vec3::new(0.1, 1.1, 0.1), Vec3::new(-3.0, 1.1, 1.6)),
        ("stool", Vec3::splat(0.25), Vec3::new(1.6, 0.25, 1.2)),
        (
            "shelf",
            Vec3::new(0.15, 0.03, 0.8),
            Vec3::new(-3.85, 2.0, 0.5),
        ),
        ("panel", Vec3::new(0.3, 0.02, 0.3), Vec3::new(0.5, 2.5, 0.5)),
    ];
    for (name, half, at) in furniture {
        boxed(&mut s, name, half, at, wood);
    }
    s.lights.push(Light {
        kind: LightKind::Point,
        position: Vec3::new(0.0, 1.6, 0.0),
        direction: Vec3::NEG_Y,
        color: Vec3::ONE,
        intensity: 6.0,
        casts_shadows: true,
        range: None,
        size: 0.0,
    });
    s.cameras.push(Camera::look_at(
        Vec3::new(3.7, 2.0, 2.7),
        Vec3::new(-2.0, 1.5, -1.5),
        80f32.to_radians(),
        0.05,
    ));
    s
}

/// A 24 m yard (ground, a box, a post, a low wall) under `lights`, camera 0 above a corner.
fn yard_scene(name: &str, lights: Vec<Light>) -> Scene {
    let mut s = Scene {
        name: name.into(),
        ..Default::default()
    };
    add_object(
        &mut s,
        "ground",
        plane(24.0, 1.0),
        colored(Vec3::splat(0.8), 1.0),
        Mat4::IDENTITY,
    );
    let red = Vec3::new(0.7, 0.2, 0.1);
    boxed(&mut s, "box", Vec3::ONE, Vec3::Y, red);
    boxed(
        &mut s,
        "post",
        Vec3::new(0.15, 1.5, 0.15),
        Vec3::new(3.0, 1.5, -1.0),
        red,
    );
    boxed(
        &mut s,
        "wall",
        Vec3::new(2.0, 0.4, 0.1),
        Vec3::new(-2.5, 0.4, 2.5),
        red,
    );
    s.lights = lights;
    s.cameras.push(Camera::look_at(
        Vec3::new(4.5, 5.0, 7.0),
        Vec3::new(0.0, 0.0, 0.5),
        55f32.to_radians(),
        0.1,
    ));
    s
}

/// The yard under a sun (light 0) and a spot lamp aimed at the box (light 1).
pub fn sun_and_spot_scene() -> Scene {
    let at = Vec3::new(-3.0, 5.0, 3.0);
    let spot = Light {
        kind: LightKind::Spot {
            inner: 0.45,
            outer: 0.6,
        },
        position: at,
        direction: (Vec3::new(0.5, 0.0, -0.5) - at).normalize(),
        color: Vec3::ONE,
        intensity: 40.0,
        casts_shadows: true,
        range: None,
        size: 0.0,
    };
    let sun = Light::sun(Vec3::new(0.4, -1.0, 0.3), 2.0);
    yard_scene("sun and spot", vec![sun, spot])
}

/// The yard under two suns from different sides.
pub fn two_suns_scene() -> Scene {
    let a = Light::sun(Vec3::new(0.5, -1.0, 0.2), 1.2);
    let b = Light::sun(Vec3::new(-0.7, -0.8, 0.4), 0.8);
    yard_scene("two suns", vec![a, b])
}

/// The yard lit in physical units, as Bevy's MixedLightingExample is: a sun of 10,000 lux (light
/// 0) and two warm lamps of 1,000 cd 1.2 m above the ground (lights 1, 2). At raw values it is a
/// white sheet; auto exposure brings it to the display (`umbra render --synthetic lux-yard`; a
/// sky's ambient, `--ambient 800`, lifts its shadows).
pub fn lux_yard_scene() -> Scene {
    let sun = Light {
        color: Vec3::new(1.0, 0.96, 0.9),
        ..Light::sun(Vec3::new(0.4, -0.8, 0.3), 1e4)
    };
    let lamp = |position: Vec3| Light {
        kind: LightKind::Point,
        position,
        direction: Vec3::NEG_Y,
        color: Vec3::new(1.0, 0.8, 0.6),
        intensity: 1e3,
        casts_shadows: true,
        range: None,
        size: 0.0,
    };
    yard_scene(
        "yard in lux",
        vec![
            sun,
            lamp(Vec3::new(-1.6, 1.2, 1.6)),
            lamp(Vec3::new(2.2, 1.2, 0.6)),
        ],
    )
}

/// The names [`by_name`] knows, besides `spheres:N` (1 ≤ N ≤ 256).
pub const NAMES: [&str; 12] = [
    "double-sided",
    "close-up",
    "foliage",
    "foliage-masked",
    "town",
    "town-mover",
    "grazing",
    "stability",
    "room",
    "sun-and-spot",
    "two-suns",
    "lux-yard",
];

/// The generated scene called `name`: `double-sided`, `close-up`, `foliage`, `foliage-masked`,
/// `town`, `grazing`, `stability`, `room`,
/// `sun-and-spot`, `two-suns`, `lux-yard` or `spheres:N` (1 ≤ N ≤ 256); `None` for any other
/// name.
pub fn by_name(name: &str) -> Option<Scene> {
    match name {
        "room" => Some(room_scene()),
        "sun-and-spot" => Some(sun_and_spot_scene()),
        "two-suns" => Some(two_suns_scene()),
        "lux-yard" => Some(lux_yard_scene()),
        "double-sided" => Some(double_sided_scene()),
        "close-up" => Some(close_up_scene()),
        "foliage" => Some(crate::scene::built::foliage::foliage_scene(
            crate::scene::AlphaMode::Blend,
        )),
        "foliage-masked" => Some(crate::scene::built::foliage::foliage_scene(
            crate::scene::AlphaMode::Mask(0.5),
        )),
        "town" => Some(town_scene()),
        "town-mover" => Some(town_mover_scene()),
        "grazing" => Some(grazing_scene()),
        "stability" => Some(stability_scene()),
        _ => match name.strip_prefix("spheres:").map(str::parse::<u32>) {
            Some(Ok(n)) if (1..=256).contains(&n) => Some(sphere_grid(n)),
            _ => None,
        },
    }
}

#[cfg(test)]
mod tests;
