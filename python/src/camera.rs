//! pyrender-shaped cameras: a projection, placed by the 4×4 world-from-camera pose given to
//! `render` (the camera looks down its −Z, Y up, as in glTF and pyrender).

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use umbra::scene::{Camera, Projection};

/// A perspective camera.
#[pyclass(module = "umbra", frozen)]
#[derive(Clone, Debug)]
pub struct PerspectiveCamera {
    /// Vertical field of view, radians.
    #[pyo3(get)]
    pub yfov: f32,
    /// Near plane distance.
    #[pyo3(get)]
    pub znear: f32,
    /// Far plane distance (None: infinite, reversed-z).
    #[pyo3(get)]
    pub zfar: Option<f32>,
    /// Width / height it was made for (None: the image's); umbra draws square pixels, so an
    /// aspect given must match the renderer's image.
    #[pyo3(get)]
    pub aspect: Option<f32>,
}

#[pymethods]
impl PerspectiveCamera {
    /// A perspective camera of vertical field of view `yfov` (radians), near plane `znear` and
    /// far plane `zfar` (None: infinite).
    #[new]
    #[pyo3(signature = (yfov, znear = 0.05, zfar = None, aspect = None))]
    fn new(yfov: f32, znear: f32, zfar: Option<f32>, aspect: Option<f32>) -> PyResult<Self> {
        if !(yfov.is_finite() && yfov > 0.0 && yfov < std::f32::consts::PI) {
            return Err(PyValueError::new_err(format!(
                "yfov {yfov} must be within (0, π) radians"
            )));
        }
        if !(znear.is_finite() && znear > 0.0) {
            return Err(PyValueError::new_err(format!(
                "znear {znear} must be above 0"
            )));
        }
        if let Some(f) = zfar.filter(|f| !(f.is_finite() && *f > znear)) {
            return Err(PyValueError::new_err(format!(
                "zfar {f} must be beyond znear"
            )));
        }
        if let Some(a) = aspect.filter(|a| !(a.is_finite() && *a > 0.0)) {
            return Err(PyValueError::new_err(format!("aspect {a} must be above 0")));
        }
        Ok(Self {
            yfov,
            znear,
            zfar,
            aspect,
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "PerspectiveCamera(yfov={}, znear={}, zfar={:?}, aspect={:?})",
            self.yfov, self.znear, self.zfar, self.aspect
        )
    }
}

/// An orthographic camera.
#[pyclass(module = "umbra", frozen)]
#[derive(Clone, Debug)]
pub struct OrthographicCamera {
    /// Half the width of the view volume (in an image of aspect xmag / ymag).
    #[pyo3(get)]
    pub xmag: f32,
    /// Half the height of the view volume.
    #[pyo3(get)]
    pub ymag: f32,
    /// Near plane distance.
    #[pyo3(get)]
    pub znear: f32,
    /// Far plane distance.
    #[pyo3(get)]
    pub zfar: f32,
}

#[pymethods]
impl OrthographicCamera {
    /// An orthographic camera seeing ±`ymag` vertically (±`ymag` × the image's aspect ratio
    /// horizontally: ±`xmag` in an image of aspect xmag / ymag) between `znear` and `zfar`.
    #[new]
    #[pyo3(signature = (xmag, ymag, znear = 0.05, zfar = 100.0))]
    fn new(xmag: f32, ymag: f32, znear: f32, zfar: f32) -> PyResult<Self> {
        for (name, m) in [("xmag", xmag), ("ymag", ymag)] {
            if !(m.is_finite() && m > 0.0) {
                return Err(PyValueError::new_err(format!("{name} {m} must be above 0")));
            }
        }
        if !(znear.is_finite() && znear >= 0.0 && zfar.is_finite() && zfar > znear) {
            return Err(PyValueError::new_err(format!(
                "znear {znear} and zfar {zfar} must satisfy 0 <= znear < zfar"
            )));
        }
        Ok(Self {
            xmag,
            ymag,
            znear,
            zfar,
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "OrthographicCamera(xmag={}, ymag={}, znear={}, zfar={})",
            self.xmag, self.ymag, self.znear, self.zfar
        )
    }
}

/// The world-from-view transform of the camera pose `m` given as argument `name`
/// (`Camera::rigid_pose`: its scale left out); a ValueError naming it for a matrix that places
/// no camera.
pub fn camera_pose(m: glam::Mat4, name: &str) -> PyResult<glam::Mat4> {
    Camera::rigid_pose(m).map_err(|e| PyValueError::new_err(format!("{name}: {e}")))
}

/// The engine camera of a Python camera object placed at `world_from_view` (a rigid pose, from
/// `camera_pose`), for an image of `aspect`.
pub fn engine_camera(
    camera: &Bound<'_, PyAny>,
    world_from_view: glam::Mat4,
    aspect: f32,
) -> PyResult<Camera> {
    if let Ok(p) = camera.cast::<PerspectiveCamera>() {
        let p = p.get();
        if let Some(a) = p.aspect.filter(|a| (a - aspect).abs() > 1e-3 * aspect) {
            return Err(PyValueError::new_err(format!(
                "the camera's aspect {a} differs from the image's {aspect} (umbra draws square \
                 pixels: leave aspect None or match width / height)"
            )));
        }
        return Ok(Camera {
            world_from_view,
            projection: Projection::Perspective { fov_y: p.yfov },
            near: p.znear,
            far: p.zfar,
        });
    }
    if let Ok(o) = camera.cast::<OrthographicCamera>() {
        let o = o.get();
        return Ok(Camera {
            world_from_view,
            projection: Projection::Orthographic {
                xmag: o.xmag,
                ymag: o.ymag,
            },
            near: o.znear,
            far: Some(o.zfar),
        });
    }
    Err(PyValueError::new_err(
        "camera must be an umbra.PerspectiveCamera or an umbra.OrthographicCamera",
    ))
}

/// The Python camera and pose of an engine camera.
pub fn python_camera<'py>(
    py: Python<'py>,
    c: &Camera,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let camera = match c.projection {
        Projection::Perspective { fov_y } => Bound::new(
            py,
            PerspectiveCamera {
                yfov: fov_y,
                znear: c.near,
                zfar: c.far,
                aspect: None,
            },
        )?
        .into_any(),
        Projection::Orthographic { xmag, ymag } => Bound::new(
            py,
            OrthographicCamera {
                xmag,
                ymag,
                znear: c.near,
                zfar: c.far_plane().unwrap_or(c.near + 1.0),
            },
        )?
        .into_any(),
    };
    Ok((camera, crate::arrays::matrix_out(py, c.world_from_view)))
}
