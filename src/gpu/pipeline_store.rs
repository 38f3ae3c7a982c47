//! The context's pipeline store: every pipeline made on a context, kept for the context's life
//! and handed out again to whoever asks for the same one.
//!
//! A driver's `VkPipelineCache` spares the compiler's front end at best; lavapipe (Mesa 22.3)
//! keeps nothing in it, and compiles each pipeline's shaders again, then their machine code at
//! the first draw. A pipeline kept alive keeps both. So a renderer made after another one on
//! the same context (a test's second method, a Python user's next scene, a batch's next size)
//! finds its pipelines made and warm.
//!
//! A pipeline is known by what it is made from, never by handles: the SPIR-V of its modules and
//! the definitions of its layout's sets and push-constant ranges (noted here as they are
//! created: [`PipelineStore::note`]) and everything else its create info says, hashed by the
//! caller ([`PipelineStore::get_or_create`]). Pipeline layouts created alike are compatible, so
//! a pipeline made with one renderer's layout binds with another's.
//!
//! The store owns what it hands out: passes never destroy a pipeline; the context does, when it
//! is dropped.

use ash::vk;
use std::collections::HashMap;
use std::hash::{Hash, Hasher};
use std::sync::{Arc, Mutex};

/// Pipelines by what they are made from, and what each live module and layout is made from.
#[derive(Default)]
pub(crate) struct PipelineStore {
    inner: Mutex<Inner>,
}

#[derive(Default)]
struct Inner {
    /// A module's, set layout's or pipeline layout's type and raw handle → the hash of its
    /// definition. The type is part of the key: Vulkan does not promise non-dispatchable handles
    /// of different types distinct values. A handle the driver hands out again after a destroy is
    /// noted again when it is created.
    made_of: HashMap<(vk::ObjectType, u64), u64>,
    /// The hash of a pipeline's definition → the pipeline, once made. Each entry has a lock of
    /// its own, held while it is made: pipelines of different definitions are made in parallel
    /// (the camera pass makes its variants on several threads), one definition once.
    pipelines: HashMap<u64, Arc<Mutex<Option<vk::Pipeline>>>>,
}

/// A hasher for definitions (std's SipHash, fixed keys: the same definition hashes the same in
/// every context of the process).
pub(crate) fn hasher() -> std::collections::hash_map::DefaultHasher {
    std::collections::hash_map::DefaultHasher::new()
}

impl PipelineStore {
    fn lock(&self) -> std::sync::MutexGuard<'_, Inner> {
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Notes what `handle` (a module, set layout or pipeline layout just created) is made of.
    pub(crate) fn note<H: vk::Handle>(&self, handle: H, definition: u64) {
        self.lock()
            .made_of
            .insert((H::TYPE, handle.as_raw()), definition);
    }

    /// What `handle` is made of (hashed), if it was noted.
    pub(crate) fn made_of<H: vk::Handle>(&self, handle: H) -> Option<u64> {
        self.lock()
            .made_of
            .get(&(H::TYPE, handle.as_raw()))
            .copied()
    }

    /// Hashes what a module or layout is made of into `state`: its noted definition, or its handle
    /// (which keys it correctly while it lives) for one made outside `gpu::shaders`: none is, and
    /// a debug build (the tests') says so if one ever is.
    pub(crate) fn hash_made_of<H: vk::Handle + Copy + std::fmt::Debug, S: Hasher>(
        &self,
        handle: H,
        state: &mut S,
    ) {
        match self.made_of(handle) {
            Some(d) => (0u8, d).hash(state),
            None => {
                debug_assert!(false, "{handle:?} was not made by gpu::shaders");
                (1u8, handle.as_raw()).hash(state)
            }
        }
    }

    /// The pipeline made from `definition`, made by `create` the first time it is asked for.
    pub(crate) fn get_or_create<E>(
        &self,
        definition: u64,
        create: impl FnOnce() -> Result<vk::Pipeline, E>,
    ) -> Result<vk::Pipeline, E> {
        let entry = self.lock().pipelines.entry(definition).or_default().clone();
        let mut slot = entry.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(p) = *slot {
            return Ok(p);
        }
        let p = create()?;
        *slot = Some(p);
        Ok(p)
    }

    /// How many pipelines the store holds.
    pub(crate) fn len(&self) -> usize {
        let made = |e: &Arc<Mutex<Option<vk::Pipeline>>>| e.lock().is_ok_and(|p| p.is_some());
        self.lock().pipelines.values().filter(|e| made(e)).count()
    }

    /// Destroys every pipeline (the context's drop, before the device).
    ///
    /// # Safety
    /// No command buffer that binds one of them may be pending, and none may be used again.
    pub(crate) unsafe fn destroy(&self, device: &ash::Device) {
        let mut inner = self.lock();
        for (_, entry) in inner.pipelines.drain() {
            if let Some(p) = *entry.lock().unwrap_or_else(|e| e.into_inner()) {
                unsafe { device.destroy_pipeline(p, None) };
            }
        }
        inner.made_of.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ash::vk::Handle;

    #[test]
    fn one_pipeline_per_definition() {
        let store = PipelineStore::default();
        let mut made = 0;
        let mut make = |raw| {
            made += 1;
            Ok::<_, ()>(vk::Pipeline::from_raw(raw))
        };
        let a = store.get_or_create(7, || make(100)).unwrap();
        let b = store.get_or_create(7, || make(200)).unwrap();
        let c = store.get_or_create(8, || make(300)).unwrap();
        assert_eq!((a.as_raw(), b.as_raw(), c.as_raw()), (100, 100, 300));
        assert_eq!(store.len(), 2);
        // A failed creation stores nothing.
        assert!(store
            .get_or_create(9, || Err::<vk::Pipeline, _>(()))
            .is_err());
        assert_eq!(store.len(), 2);
    }

    /// One definition being made does not hold up another (the camera pass makes its variants
    /// on several threads; made one at a time, the demo's first frame took 95 ms longer).
    #[test]
    fn different_pipelines_are_made_in_parallel() {
        let store = PipelineStore::default();
        let (tx, rx) = std::sync::mpsc::channel();
        let store = &store;
        std::thread::scope(|s| {
            let waiting = s.spawn(move || {
                store.get_or_create(1, || {
                    // Made while pipeline 2 is made on the other thread.
                    let other = rx.recv_timeout(std::time::Duration::from_secs(5));
                    other.map(|()| vk::Pipeline::from_raw(1))
                })
            });
            std::thread::sleep(std::time::Duration::from_millis(50));
            let second = store.get_or_create(2, || {
                tx.send(()).unwrap();
                Ok::<_, std::sync::mpsc::RecvTimeoutError>(vk::Pipeline::from_raw(2))
            });
            assert!(second.is_ok());
            let first = waiting.join().unwrap();
            assert!(first.is_ok(), "pipeline 2 waited for pipeline 1 to be made");
        });
        assert_eq!(store.len(), 2);
    }

    #[test]
    fn modules_are_known_by_content_not_handle() {
        let store = PipelineStore::default();
        let key = |h: u64| {
            let mut s = hasher();
            store.hash_made_of(vk::ShaderModule::from_raw(h), &mut s);
            s.finish()
        };
        store.note(vk::ShaderModule::from_raw(1), 42);
        store.note(vk::ShaderModule::from_raw(2), 42);
        assert_eq!(key(1), key(2), "two modules of the same SPIR-V");
        // The driver hands handle 1 out again for other SPIR-V.
        store.note(vk::ShaderModule::from_raw(1), 43);
        assert_ne!(key(1), key(2));
    }

    /// A module and a layout that share a raw value (Vulkan allows it across types) keep their
    /// own definitions.
    #[test]
    fn handles_of_different_types_are_kept_apart() {
        let store = PipelineStore::default();
        store.note(vk::ShaderModule::from_raw(7), 42);
        store.note(vk::PipelineLayout::from_raw(7), 43);
        assert_eq!(store.made_of(vk::ShaderModule::from_raw(7)), Some(42));
        assert_eq!(store.made_of(vk::PipelineLayout::from_raw(7)), Some(43));
        assert_eq!(store.made_of(vk::DescriptorSetLayout::from_raw(7)), None);
    }

    #[test]
    #[cfg(debug_assertions)]
    #[should_panic(expected = "was not made by gpu::shaders")]
    fn a_module_made_elsewhere_is_caught() {
        PipelineStore::default().hash_made_of(vk::ShaderModule::from_raw(3), &mut hasher());
    }
}
