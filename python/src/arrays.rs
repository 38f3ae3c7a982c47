//! numpy in and out: any array-like converted (`numpy.ascontiguousarray`) to the dtype a call
//! needs and checked for shape, frames returned as arrays of the documented shapes, and the room
//! a batch's stacked arrays need asked for before it renders.

use glam::Mat4;
use numpy::ndarray::{Array2, ArrayD, IxDyn};
use numpy::{Element, IntoPyArray, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::{PyMemoryError, PyValueError};
use pyo3::prelude::*;

/// `obj` as a contiguous array of `dtype`: its values in C order and its shape.
pub fn values<T: Element + Copy>(
    obj: &Bound<'_, PyAny>,
    dtype: &str,
    name: &str,
) -> PyResult<(Vec<T>, Vec<usize>)> {
    let np = obj.py().import("numpy")?;
    let a = np
        .call_method1("ascontiguousarray", (obj, dtype))
        .map_err(|e| PyValueError::new_err(format!("{name}: not an array of numbers ({e})")))?;
    let a = a.cast_into::<PyArrayDyn<T>>()?;
    let shape = a.shape().to_vec();
    let ro = a.readonly();
    Ok((ro.as_slice()?.to_vec(), shape))
}

/// An (H, W, 3|4) uint8 array as RGBA8 pixels (opaque where it has no alpha): width, height and
/// the pixels; a one-line error naming `name` for any other shape.
pub fn rgba8(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<(u32, u32, Vec<u8>)> {
    let (v, shape) = values::<u8>(obj, "uint8", name)?;
    let (h, w, k) = match shape.as_slice() {
        [h, w, k @ (3 | 4)] if *h > 0 && *w > 0 => (*h, *w, *k),
        _ => {
            return Err(PyValueError::new_err(format!(
                "{name}: shape {shape:?}, expected (h, w, 3) or (h, w, 4)"
            )))
        }
    };
    let rgba = v
        .chunks_exact(k)
        .flat_map(|c| [c[0], c[1], c[2], if k == 4 { c[3] } else { 255 }])
        .collect();
    Ok((w as u32, h as u32, rgba))
}

/// `obj` as rows of `N` floats: an (n, N) array (or a flat one of n·N values).
pub fn rows<const N: usize>(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec<[f32; N]>> {
    let (v, shape) = values::<f32>(obj, "float32", name)?;
    let ok = match shape.as_slice() {
        [_, n] => *n == N,
        [n] => n % N == 0,
        _ => false,
    };
    if !ok {
        return Err(PyValueError::new_err(format!(
            "{name}: shape {shape:?}, expected (n, {N})"
        )));
    }
    Ok(v.chunks_exact(N)
        .map(|c| std::array::from_fn(|k| c[k]))
        .collect())
}

/// A 4×4 matrix (row-major numpy, as pyrender's poses) as a glam matrix.
pub fn matrix4(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Mat4> {
    let (v, shape) = values::<f32>(obj, "float32", name)?;
    if shape != [4, 4] {
        return Err(PyValueError::new_err(format!(
            "{name}: shape {shape:?}, expected (4, 4)"
        )));
    }
    let m = Mat4::from_cols_slice(&v).transpose();
    if !m.is_finite() {
        return Err(PyValueError::new_err(format!(
            "{name}: holds a NaN or an infinity"
        )));
    }
    Ok(m)
}

/// A glam matrix as a row-major (4, 4) float64 array.
pub fn matrix_out<'py>(py: Python<'py>, m: Mat4) -> Bound<'py, PyAny> {
    let rows: Vec<f64> = m
        .transpose()
        .to_cols_array()
        .iter()
        .map(|&x| x as f64)
        .collect();
    Array2::from_shape_vec((4, 4), rows)
        .expect("16 values")
        .into_pyarray(py)
        .into_any()
}

/// `data` (row-major: `frames` images of `c` values a pixel) as an array of shape
/// ([frames,] h, w[, c]): the frame axis only when `stacked`, the channel axis only when `c` > 1.
pub fn image_out<'py, T: Element>(
    py: Python<'py>,
    data: Vec<T>,
    (w, h): (u32, u32),
    c: usize,
    stacked: Option<usize>,
) -> Bound<'py, PyAny> {
    let mut shape: Vec<usize> = stacked.into_iter().collect();
    shape.extend([h as usize, w as usize]);
    if c > 1 {
        shape.push(c);
    }
    ArrayD::from_shape_vec(IxDyn(&shape), data)
        .expect("the values fill the shape")
        .into_pyarray(py)
        .into_any()
}

/// A MemoryError, before anything is rendered, for a batch of `n` frames whose stacked arrays
/// of `outputs` at `w`×`h` this process cannot have (colour 3 bytes a pixel, normals 12, the
/// others 4): allocating them after the first frame would abort the interpreter.
pub fn check_room(outputs: &[&str], (w, h): (u32, u32), n: usize) -> PyResult<()> {
    let per_pixel: usize = outputs
        .iter()
        .map(|o| match *o {
            "color" => 3,
            "normals" => 12,
            _ => 4,
        })
        .sum();
    let total = per_pixel
        .saturating_mul(w as usize * h as usize)
        .saturating_mul(n);
    if Vec::<u8>::new().try_reserve_exact(total).is_err() {
        return Err(PyMemoryError::new_err(format!(
            "render_batch: {n} frames of {} at {w}x{h} take {:.1} GB as stacked arrays, more than \
             this process can allocate: render the poses in smaller batches",
            outputs.join(", "),
            total as f64 / 1e9
        )));
    }
    Ok(())
}
