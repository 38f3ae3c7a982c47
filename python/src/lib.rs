//! `umbra._umbra`: the Python bindings, a thin shell over the engine. A scene (loaded from glTF or
//! built from numpy arrays), pyrender-shaped cameras, and an offscreen renderer whose `render`
//! returns numpy arrays (colour, depth, segmentation, normals, shadow visibility) and releases the
//! GIL while the GPU works. The Python package `umbra` (python/pysrc/umbra) re-exports these and
//! adds the trimesh and Ray helpers.

mod arrays;
mod camera;
mod golden;
mod render;
mod scene;
mod settings;

use pyo3::prelude::*;

pyo3::create_exception!(
    umbra,
    UmbraError,
    pyo3::exceptions::PyException,
    "Any error umbra reports (its message is the command line's one line)."
);
pyo3::create_exception!(
    umbra,
    LoadError,
    UmbraError,
    "A scene that cannot be loaded: missing, unreadable, corrupt or unsupported glTF."
);
pyo3::create_exception!(
    umbra,
    GpuError,
    UmbraError,
    "No usable Vulkan device, or a device error while rendering."
);

/// A `GpuError` exception from the engine's error.
pub(crate) fn gpu_error(e: umbra::GpuError) -> PyErr {
    GpuError::new_err(e.to_string())
}

/// Loads a glTF 2.0 file (`.gltf` or `.glb`) as a `Scene`; raises `LoadError` with the command
/// line's one-line message when it cannot.
#[pyfunction]
fn load(path: std::path::PathBuf) -> PyResult<scene::PyScene> {
    scene::PyScene::load(path)
}

#[pymodule]
fn _umbra(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("UmbraError", py.get_type::<UmbraError>())?;
    m.add("LoadError", py.get_type::<LoadError>())?;
    m.add("GpuError", py.get_type::<GpuError>())?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(golden::golden_check, m)?)?;
    m.add_function(wrap_pyfunction!(golden::write_report, m)?)?;
    m.add("GoldenMismatch", py.get_type::<golden::GoldenMismatch>())?;
    m.add_class::<scene::PyScene>()?;
    m.add_class::<camera::PerspectiveCamera>()?;
    m.add_class::<camera::OrthographicCamera>()?;
    m.add_class::<render::OffscreenRenderer>()?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
