//! The passes and what they share: the shadow depth pass and its cache of unchanged layers, the
//! camera pass with its deferred path and receiver split, and the camera's draw selection.

pub(crate) mod camera;
pub(crate) mod cull;
pub(crate) mod deferred;
pub(crate) mod exact;
pub(crate) mod post_aa;
pub(crate) mod receivers;
pub(crate) mod screen;
pub(crate) mod shadow_cache;
pub(crate) mod shadow_pass;
