use super::*;

fn image(n: u64) -> Attachment {
    use ash::vk::Handle;
    Attachment {
        image: vk::Image::from_raw(n),
        view: vk::ImageView::null(),
        aspect: vk::ImageAspectFlags::COLOR,
        state: Access::Undefined,
    }
}

/// The memory barrier one use of a buffer derives, as (src, dst).
fn buffer_barrier(state: &mut BufferState, to: BufferAccess) -> Option<((S, A), (S, A))> {
    let mut u = Uses::new();
    u.buffers.push((state, to));
    let (memory, _) = u.barriers();
    memory.map(|m| {
        (
            (m.src_stage_mask, m.src_access_mask),
            (m.dst_stage_mask, m.dst_access_mask),
        )
    })
}

#[test]
fn image_barriers_follow_each_images_last_access() {
    let (mut a, mut b) = (image(1), image(2));
    let (_, first) = Uses::new()
        .writes(&mut a, Access::ColorAttachment)
        .writes(&mut b, Access::ColorAttachment)
        .barriers();
    assert_eq!(first.len(), 2);
    assert_eq!(first[0].old_layout, vk::ImageLayout::UNDEFINED);
    assert_eq!(
        first[1].new_layout,
        vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL
    );
    // Sampled after being drawn: the writes are made available to the fragment shader.
    let (_, second) = Uses::new()
        .reads(&mut a, Access::FragmentSampled)
        .barriers();
    assert_eq!(second.len(), 1);
    assert_eq!(
        second[0].old_layout,
        vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL
    );
    assert_eq!(second[0].src_access_mask, A::COLOR_ATTACHMENT_WRITE);
    assert_eq!(a.state, Access::FragmentSampled);
    assert_eq!(b.state, Access::ColorAttachment);
    // Read again the same way: nothing to wait for. Written again: always a barrier.
    let (_, again) = Uses::new()
        .reads(&mut a, Access::FragmentSampled)
        .barriers();
    assert!(again.is_empty());
    let (_, rewrite) = Uses::new()
        .writes(&mut b, Access::ColorAttachment)
        .barriers();
    assert_eq!(rewrite.len(), 1);
}

#[test]
fn buffer_barriers_follow_writes_and_the_reads_since() {
    let mut s = BufferState::default();
    // First use: nothing to wait for.
    assert_eq!(buffer_barrier(&mut s, BufferAccess::TransferWrite), None);
    // A compute write after a fill: waits for the fill's write.
    let rw = A::SHADER_STORAGE_READ | A::SHADER_STORAGE_WRITE;
    assert_eq!(
        buffer_barrier(&mut s, BufferAccess::ComputeWrite),
        Some((
            (S::ALL_TRANSFER, A::TRANSFER_WRITE),
            (S::COMPUTE_SHADER, rw)
        ))
    );
    // Read by fragments: the compute write made visible to them; read again, nothing.
    assert_eq!(
        buffer_barrier(&mut s, BufferAccess::FragmentRead),
        Some((
            (S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE),
            (S::FRAGMENT_SHADER, A::SHADER_STORAGE_READ)
        ))
    );
    assert_eq!(buffer_barrier(&mut s, BufferAccess::FragmentRead), None);
    // Read by vertex shaders too: the write is not yet visible there.
    assert!(buffer_barrier(&mut s, BufferAccess::VertexRead).is_some());
    // Written again: waits for the write and, without access, for both readers.
    assert_eq!(
        buffer_barrier(&mut s, BufferAccess::TransferWrite),
        Some((
            (
                S::COMPUTE_SHADER | S::FRAGMENT_SHADER | S::VERTEX_SHADER,
                A::SHADER_STORAGE_WRITE
            ),
            (S::ALL_TRANSFER, A::TRANSFER_WRITE)
        ))
    );
    // The host's read waits for the copy; the next write does not wait for the host.
    assert!(buffer_barrier(&mut s, BufferAccess::HostRead).is_some());
    assert_eq!(
        buffer_barrier(&mut s, BufferAccess::TransferWrite),
        Some((
            (S::ALL_TRANSFER, A::TRANSFER_WRITE),
            (S::ALL_TRANSFER, A::TRANSFER_WRITE)
        ))
    );
}
