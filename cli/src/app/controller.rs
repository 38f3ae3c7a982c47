//! Camera controllers for the viewer, as pure logic (input events → camera state) so they can be
//! unit-tested without a window: orbit (left-drag rotate, right/middle-drag pan, wheel zoom,
//! frame the bounds) and fly (WASD + Q/E, mouse look with the left button, Shift for speed),
//! either through a perspective or an orthographic projection. Speeds scale with the scene's
//! size.

use glam::Vec3;
use umbra::math::Aabb;
use umbra::scene::mesh::framing::{fit_box, FILL, FOV_Y_DEG};
use umbra::scene::{Camera, Projection};

/// Mouse buttons the controllers use.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Button {
    /// Rotate (orbit) or look (fly).
    Left,
    /// Pan.
    Right,
    /// Pan.
    Middle,
}

/// Movement keys.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MoveKey {
    /// Forward.
    W,
    /// Left.
    A,
    /// Back.
    S,
    /// Right.
    D,
    /// Down.
    Q,
    /// Up.
    E,
    /// Faster.
    Shift,
}

/// An input event.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Input {
    /// Button pressed.
    Press(Button),
    /// Button released.
    Release(Button),
    /// Cursor moved to (x, y) pixels.
    Cursor(f32, f32),
    /// Wheel scrolled by lines (positive = away from the user = zoom in).
    Scroll(f32),
    /// Movement key down/up.
    Key(MoveKey, bool),
}

/// Orbit or fly.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Around a target point.
    Orbit,
    /// Free flight.
    Fly,
}

/// Camera state driven by input.
#[derive(Clone, Debug)]
pub struct Controller {
    /// Current mode.
    pub mode: Mode,
    /// Orbit centre.
    pub target: Vec3,
    /// Orbit distance.
    pub distance: f32,
    /// Heading (radians, around +Y).
    pub yaw: f32,
    /// Elevation (radians).
    pub pitch: f32,
    /// Fly position.
    pub position: Vec3,
    /// Vertical field of view (perspective; an orthographic view spans what it spans at the
    /// orbit distance).
    pub fov_y: f32,
    /// Orthographic (parallel) projection: ±distance·tan(fov_y / 2) vertically, the eye drawn
    /// back by the scene's size so nothing in front of the orbit centre is clipped.
    pub orthographic: bool,
    /// Scene size (bounds diagonal) that scales speeds and the near plane.
    pub scale: f32,
    /// Near-plane distance of the camera this controller continues from (its own near plane
    /// while no larger than the scale's: a street-level camera in a town keeps the ground at
    /// its feet); None after framing.
    pub near: Option<f32>,
    held: Vec<MoveKey>,
    drag: Option<Button>,
    cursor: Option<(f32, f32)>,
}

/// Radians per pixel of drag.
pub const ROTATE_SPEED: f32 = 0.005;
/// Fraction of the orbit distance panned per pixel.
pub const PAN_SPEED: f32 = 0.0015;
/// Zoom factor per wheel line.
pub const ZOOM_STEP: f32 = 0.9;
/// Fly speed in scene sizes per second (×4 with Shift).
pub const FLY_SPEED: f32 = 0.25;

impl Controller {
    /// A controller that frames `bounds` (orbit mode) in a square or wider view.
    pub fn framing(bounds: &Aabb) -> Self {
        let mut c = Self {
            mode: Mode::Orbit,
            target: Vec3::ZERO,
            distance: 1.0,
            yaw: 0.5,
            pitch: 0.4,
            position: Vec3::ZERO,
            fov_y: FOV_Y_DEG.to_radians(),
            orthographic: false,
            scale: 1.0,
            near: None,
            held: Vec::new(),
            drag: None,
            cursor: None,
        };
        c.frame(bounds, 1.0);
        c
    }

    /// A controller continuing from `camera` (orbiting the point ahead of it level with the
    /// bounds' centre; an orthographic camera keeps its height of view).
    pub fn from_camera(camera: &Camera, bounds: &Aabb) -> Self {
        let mut c = Self::framing(bounds);
        let eye = camera.position();
        let forward = camera.forward();
        let dist = if bounds.is_empty() {
            1.0
        } else {
            (bounds.center() - eye).dot(forward).max(c.scale * 0.05)
        };
        c.pitch = (-forward.y).clamp(-1.0, 1.0).asin();
        c.yaw = (-forward.x).atan2(-forward.z);
        c.near = Some(camera.near).filter(|n| n.is_finite() && *n > 0.0);
        match camera.projection {
            Projection::Perspective { fov_y } => {
                c.fov_y = fov_y;
                c.orthographic = false;
                c.target = eye + forward * dist;
                c.distance = dist;
                c.position = eye;
            }
            Projection::Orthographic { ymag, .. } => {
                c.orthographic = true;
                c.distance = ymag / (c.fov_y * 0.5).tan();
                c.target = eye + forward * dist;
                c.position = c.target - forward * c.distance;
            }
        }
        c
    }

    /// Orbit to frame `bounds` in a view of `aspect` from the current direction (the `F` key):
    /// the box centred, filling the same share of the shorter side as the default view.
    pub fn frame(&mut self, bounds: &Aabb, aspect: f32) {
        let (_, radius) = bounds.bounding_sphere();
        self.scale = radius * 2.0;
        self.near = None;
        let f = fit_box(bounds, -self.forward(), self.fov_y, aspect, FILL);
        self.target = f.target;
        self.distance = (f.eye - f.target).length();
        self.mode = Mode::Orbit;
    }

    /// Switches between a perspective and an orthographic projection, keeping the size of what
    /// is seen at the orbit centre (the `O` key).
    pub fn toggle_projection(&mut self) {
        self.orthographic = !self.orthographic;
    }

    /// Switches between orbit and fly, keeping the eye where it is (the `Tab` key).
    pub fn toggle_mode(&mut self) {
        match self.mode {
            Mode::Orbit => {
                self.position = self.eye();
                self.mode = Mode::Fly;
            }
            Mode::Fly => {
                self.target = self.position + self.forward() * self.distance;
                self.mode = Mode::Orbit;
            }
        }
    }

    fn forward(&self) -> Vec3 {
        // Orbit: the eye sits at target + distance · dir(yaw, pitch) and looks back at the target.
        -Vec3::new(
            self.pitch.cos() * self.yaw.sin(),
            self.pitch.sin(),
            self.pitch.cos() * self.yaw.cos(),
        )
    }

    /// Eye position.
    pub fn eye(&self) -> Vec3 {
        match self.mode {
            Mode::Orbit => self.target - self.forward() * self.distance,
            Mode::Fly => self.position,
        }
    }

    /// Handles one input event.
    pub fn handle(&mut self, input: Input) {
        match input {
            Input::Press(b) => self.drag = Some(b),
            Input::Release(b) => {
                if self.drag == Some(b) {
                    self.drag = None;
                }
            }
            Input::Cursor(x, y) => {
                if let (Some(b), Some((px, py))) = (self.drag, self.cursor) {
                    self.drag_by(b, x - px, y - py);
                }
                self.cursor = Some((x, y));
            }
            Input::Scroll(lines) => match self.mode {
                Mode::Orbit => {
                    self.distance = (self.distance * ZOOM_STEP.powf(lines))
                        .clamp(self.scale * 1e-3, self.scale * 100.0);
                }
                Mode::Fly => self.position += self.forward() * lines * self.scale * 0.05,
            },
            Input::Key(k, down) => {
                self.held.retain(|h| *h != k);
                if down {
                    self.held.push(k);
                }
            }
        }
    }

    fn drag_by(&mut self, b: Button, dx: f32, dy: f32) {
        match (b, self.mode) {
            (Button::Left, Mode::Orbit) => {
                self.yaw -= dx * ROTATE_SPEED;
                self.pitch = (self.pitch + dy * ROTATE_SPEED).clamp(-1.55, 1.55);
            }
            (Button::Left, Mode::Fly) => {
                self.yaw -= dx * ROTATE_SPEED;
                self.pitch = (self.pitch - dy * ROTATE_SPEED).clamp(-1.55, 1.55);
            }
            (Button::Right | Button::Middle, _) => {
                let f = self.forward();
                let right = f.cross(Vec3::Y).normalize_or(Vec3::X);
                let up = right.cross(f);
                let k = self.distance * PAN_SPEED;
                let delta = (-right * dx + up * dy) * k;
                self.target += delta;
                self.position += delta;
            }
        }
    }

    /// Advances held-key movement by `dt` seconds (fly mode).
    pub fn update(&mut self, dt: f32) {
        if self.mode != Mode::Fly || self.held.is_empty() {
            return;
        }
        let f = self.forward();
        let right = f.cross(Vec3::Y).normalize_or(Vec3::X);
        let mut v = Vec3::ZERO;
        for k in &self.held {
            v += match k {
                MoveKey::W => f,
                MoveKey::S => -f,
                MoveKey::D => right,
                MoveKey::A => -right,
                MoveKey::E => Vec3::Y,
                MoveKey::Q => -Vec3::Y,
                MoveKey::Shift => Vec3::ZERO,
            };
        }
        let fast = if self.held.contains(&MoveKey::Shift) {
            4.0
        } else {
            1.0
        };
        self.position += v.normalize_or_zero() * FLY_SPEED * self.scale * fast * dt;
    }

    /// The camera for the current state.
    pub fn camera(&self) -> Camera {
        let eye = self.eye();
        let near = (self.scale * 1e-3)
            .min(self.near.unwrap_or(f32::INFINITY))
            .max(1e-5);
        let forward = self.forward();
        if self.orthographic {
            // As tall as the perspective view at the orbit centre; drawn back so that nothing
            // between the eye and the centre, or a scene's size behind the eye, is clipped.
            let ymag = self.distance * (self.fov_y * 0.5).tan();
            let back = eye - forward * self.scale;
            let far = self.scale * 2.0 + self.distance + self.scale;
            return Camera::orthographic_look_at(back, back + forward, ymag, near, far);
        }
        Camera::look_at(eye, eye + forward, self.fov_y, near)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bounds() -> Aabb {
        Aabb::new(Vec3::splat(-5.0), Vec3::splat(5.0))
    }

    #[test]
    fn framing_centres_the_bounds() {
        let c = Controller::framing(&bounds());
        let cam = c.camera();
        let m = umbra::plan::camera_projection(&cam, 1.0) * cam.view_from_world();
        let (mut lo, mut hi) = (glam::Vec2::MAX, glam::Vec2::MIN);
        for p in bounds().corners() {
            let q = m * p.extend(1.0);
            lo = lo.min(q.truncate().truncate() / q.w);
            hi = hi.max(q.truncate().truncate() / q.w);
        }
        let centre = (lo + hi) * 0.5;
        assert!(centre.abs().max_element() < 1e-3, "{centre}");
        assert!(cam.position().length() > 8.66, "outside the bounds");
    }

    #[test]
    fn left_drag_orbits_around_the_target_at_constant_distance() {
        let mut c = Controller::framing(&bounds());
        let before = c.eye();
        c.handle(Input::Cursor(100.0, 100.0));
        c.handle(Input::Press(Button::Left));
        c.handle(Input::Cursor(200.0, 100.0));
        c.handle(Input::Release(Button::Left));
        let after = c.eye();
        let t = c.target;
        assert!(((after - t).length() - (before - t).length()).abs() < 1e-3);
        assert!(
            (after - before).length() > 1.0,
            "dragging 100 px must rotate"
        );
        assert!((c.yaw - (0.5 - 100.0 * ROTATE_SPEED)).abs() < 1e-6);
        // Moving without a button held does nothing.
        c.handle(Input::Cursor(300.0, 300.0));
        assert_eq!(c.eye(), after);
    }

    #[test]
    fn right_drag_pans_and_wheel_zooms() {
        let mut c = Controller::framing(&bounds());
        let d0 = c.distance;
        c.handle(Input::Cursor(0.0, 0.0));
        c.handle(Input::Press(Button::Right));
        c.handle(Input::Cursor(50.0, 0.0));
        c.handle(Input::Release(Button::Right));
        assert!(c.target.length() > 0.1, "pan moves the target");
        assert!((c.distance - d0).abs() < 1e-6, "pan keeps the distance");
        c.handle(Input::Scroll(2.0));
        assert!((c.distance - d0 * 0.81).abs() < 1e-3);
        for _ in 0..1000 {
            c.handle(Input::Scroll(10.0));
        }
        assert!(c.distance >= c.scale * 1e-3, "zoom is clamped");
    }

    #[test]
    fn fly_moves_with_keys_at_scene_scaled_speed() {
        let mut c = Controller::framing(&bounds());
        c.toggle_mode();
        assert_eq!(c.mode, Mode::Fly);
        let start = c.eye();
        let forward = c.forward();
        c.handle(Input::Key(MoveKey::W, true));
        c.update(1.0);
        let moved = c.eye() - start;
        assert!((moved.length() - FLY_SPEED * c.scale).abs() < 1e-3);
        assert!(moved.normalize().dot(forward) > 0.999);
        c.handle(Input::Key(MoveKey::W, false));
        let here = c.eye();
        c.update(1.0);
        assert_eq!(c.eye(), here, "released keys stop");
        // Shift is four times faster; back to orbit keeps looking the same way.
        c.handle(Input::Key(MoveKey::E, true));
        c.handle(Input::Key(MoveKey::Shift, true));
        c.update(0.5);
        assert!((c.eye().y - here.y - 0.5 * 4.0 * FLY_SPEED * c.scale).abs() < 1e-3);
        let f = c.forward();
        c.toggle_mode();
        assert_eq!(c.mode, Mode::Orbit);
        assert!(c.forward().abs_diff_eq(f, 1e-6));
    }

    #[test]
    fn from_camera_keeps_the_view() {
        let cam = Camera::look_at(
            Vec3::new(3.0, 4.0, 12.0),
            Vec3::new(0.0, 1.0, 0.0),
            0.8,
            0.1,
        );
        let c = Controller::from_camera(&cam, &bounds());
        let back = c.camera();
        assert!(
            back.position().abs_diff_eq(cam.position(), 1e-3),
            "{} vs {}",
            back.position(),
            cam.position()
        );
        let f0 = cam.world_from_view.transform_vector3(-Vec3::Z);
        let f1 = back.world_from_view.transform_vector3(-Vec3::Z);
        assert!(f0.abs_diff_eq(f1, 1e-4));
    }

    #[test]
    fn orthographic_keeps_the_size_seen_at_the_centre_and_sees_it_all() {
        let mut c = Controller::framing(&bounds());
        let persp = c.camera();
        c.toggle_projection();
        let ortho = c.camera();
        let Projection::Orthographic { ymag, .. } = ortho.projection else {
            panic!("{ortho:?}");
        };
        // The perspective half-height at the orbit centre.
        let want = c.distance * (persp.fov_y().unwrap() * 0.5).tan();
        assert!((ymag - want).abs() < 1e-4, "{ymag} vs {want}");
        assert!(ortho.forward().abs_diff_eq(persp.forward(), 1e-6));
        // Every corner of the bounds lies between its near and far planes.
        let view = ortho.view_from_world();
        for p in bounds().corners() {
            let d = -view.transform_point3(p).z;
            assert!(d > ortho.near && d < ortho.far.unwrap(), "{p} at {d}");
        }
        // Back to perspective: the same camera as before.
        c.toggle_projection();
        assert_eq!(c.camera(), persp);
        // From a glTF orthographic camera: the same height of view and direction.
        let glb =
            Camera::orthographic_look_at(Vec3::new(0.0, 2.0, 20.0), Vec3::ZERO, 3.0, 0.0, 50.0);
        let c = Controller::from_camera(&glb, &bounds());
        let back = c.camera();
        assert_eq!(
            back.projection,
            Projection::Orthographic {
                xmag: 3.0,
                ymag: 3.0
            }
        );
        assert!(back.forward().abs_diff_eq(glb.forward(), 1e-5));
    }

    #[test]
    fn framing_fills_the_share_of_the_shorter_side() {
        let b = Aabb::new(Vec3::new(-4.0, 0.0, -0.2), Vec3::new(4.0, 1.0, 0.2));
        let mut c = Controller::framing(&b);
        c.frame(&b, 16.0 / 9.0);
        let cam = c.camera();
        let m = umbra::plan::camera_projection(&cam, 16.0 / 9.0) * cam.view_from_world();
        let (mut lo, mut hi) = (glam::Vec2::MAX, glam::Vec2::MIN);
        for p in b.corners() {
            let q = m * p.extend(1.0);
            let ndc = q.truncate().truncate() / q.w;
            lo = lo.min(ndc);
            hi = hi.max(ndc);
        }
        // In pixels of a 16:9 image 9 units high: the wider side spans FILL of the height.
        let span = (hi - lo) * 0.5 * glam::Vec2::new(16.0, 9.0);
        assert!((span.max_element() / 9.0 - FILL).abs() < 2e-3, "{span}");
    }
}
