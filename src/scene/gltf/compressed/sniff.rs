//! What container an image's bytes are, from their first bytes (a leaf: the report and the
//! texture steps both ask).

/// The KTX2 file identifier.
const KTX2_MAGIC: [u8; 12] = [
    0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A,
];

/// Whether `data` starts as a KTX2 file does.
pub(in crate::scene) fn is_ktx2(data: &[u8]) -> bool {
    data.starts_with(&KTX2_MAGIC)
}

/// Whether `data` starts as a WebP file does (a RIFF container of form WEBP).
pub(in crate::scene) fn is_webp(data: &[u8]) -> bool {
    data.len() >= 12 && &data[0..4] == b"RIFF" && &data[8..12] == b"WEBP"
}
