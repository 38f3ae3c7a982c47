//! The ring of frame slots a batch keeps in flight (`Renderer::render_each`): how many, and one
//! resource per slot.

use crate::gpu::context::GpuError;

/// Frames a batch keeps in flight ([`Renderer::render_each`]): view k + 1 is recorded and drawn
/// while view k is read back and handed over. Two, not three: on lavapipe (two cores, the
/// device itself on the CPU) neither ring measured faster than one frame at a time (docs/python.md,
/// *Batches*), and each slot holds its own readbacks (up to 28 bytes a pixel with normals).
pub const RING: usize = 2;

/// One of `make(slot)` per ring slot (`RING`).
pub(super) fn ring_of<T>(
    make: impl Fn(usize) -> Result<T, GpuError>,
) -> Result<[T; RING], GpuError> {
    let v = (0..RING).map(make).collect::<Result<Vec<T>, _>>()?;
    Ok(v.try_into().unwrap_or_else(|_| unreachable!("RING items")))
}
