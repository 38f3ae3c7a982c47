//! Mutation fuzzing of the glTF loader: thousands of corrupted copies of real files must each
//! load or fail with an error, without a panic (even one caught internally) or a hang.

use std::sync::atomic::{AtomicUsize, Ordering};
use umbra::scene::gltf::load_gltf;

static PANICS: AtomicUsize = AtomicUsize::new(0);
/// Panics inside a third-party decoder (Draco, Basis Universal) on a broken stream: contained
/// (the file's or image's one-line error), counted and shown apart from umbra's own.
static DECODER_PANICS: AtomicUsize = AtomicUsize::new(0);

struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

fn mutate(rng: &mut Rng, src: &[u8]) -> Vec<u8> {
    let mut b = src.to_vec();
    for _ in 0..1 + rng.below(4) {
        match rng.below(5) {
            0 => {
                let i = rng.below(b.len());
                b[i] ^= 1 << rng.below(8);
            }
            1 => {
                let i = rng.below(b.len());
                b[i] = [0, 0xff, b'"', b'9', b'-', b'{'][rng.below(6)];
            }
            2 => b.truncate(rng.below(b.len())),
            3 => {
                let i = rng.below(b.len());
                let n = rng.below(16);
                let junk: Vec<u8> = (0..n).map(|_| rng.next() as u8).collect();
                b.splice(i..i, junk);
            }
            _ => {
                // Large numbers in text: counts, offsets, lengths.
                if let Some(pos) = b
                    .windows(1)
                    .position(|w| w[0].is_ascii_digit())
                    .map(|p| p + rng.below(b.len() - p))
                {
                    if b[pos].is_ascii_digit() {
                        let big = ["4294967295", "99999999999", "-1", "1e30"][rng.below(4)];
                        b.splice(pos..pos + 1, big.bytes());
                    }
                }
            }
        }
        if b.is_empty() {
            break;
        }
    }
    b
}

#[test]
fn corrupted_files_never_panic() {
    std::panic::set_hook(Box::new(|info| {
        if umbra::scene::gltf::compressed::in_third_party_decoder() {
            DECODER_PANICS.fetch_add(1, Ordering::SeqCst);
            eprintln!("decoder panic (contained): {info}");
        } else {
            PANICS.fetch_add(1, Ordering::SeqCst);
            eprintln!("panic: {info}");
        }
    }));
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("fuzz");
    std::fs::create_dir_all(&dir).unwrap();
    // Seeds: the generated corpus (external .bin and PNG files, .glb with embedded images, data
    // URIs, samplers, textures, every material texture slot, sparse accessors, strips and fans,
    // KHR_lights_punctual, KHR_materials_unlit, cameras), written next to the mutated copies so
    // their external files resolve.
    // Also the compressed fixtures (tests/data/compressed: quantized, meshopt, Draco, KTX2 and
    // WebP, as the real tools wrote them), so mutations reach the decoders.
    let compressed = crate::common::corpus::models_under(
        &std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/compressed"),
    );
    assert!(compressed.len() >= 20, "the compressed fixtures are seeds");
    let seeds: Vec<(String, Vec<u8>)> = crate::common::corpus::write_corpus(&dir)
        .into_iter()
        .chain(compressed)
        .map(|p| {
            let name = p.file_name().unwrap().to_string_lossy().to_string();
            (name, std::fs::read(&p).unwrap())
        })
        .collect();
    let mut rng = Rng(0x5DEE_CE66_D1CE_4E5B);
    let (mut ok, mut err) = (0, 0);
    let start = std::time::Instant::now();
    let n: usize = std::env::var("UMBRA_FUZZ_ITERATIONS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(4000);
    for i in 0..n {
        let (name, src) = &seeds[i % seeds.len()];
        let p = dir.join(format!("m_{name}"));
        std::fs::write(&p, mutate(&mut rng, src)).unwrap();
        let before = PANICS.load(Ordering::SeqCst);
        let result = load_gltf(&p);
        if PANICS.load(Ordering::SeqCst) != before {
            let keep = dir.join(format!("panic_{i}_{name}"));
            let _ = std::fs::copy(&p, &keep);
            eprintln!("panicking input kept at {}", keep.display());
        }
        match result {
            Ok(_) => ok += 1,
            Err(e) => {
                err += 1;
                assert!(!e.to_string().contains('\n'), "errors are one line: {e}");
            }
        }
    }
    let _ = std::panic::take_hook();
    eprintln!(
        "{ok} loaded, {err} rejected in {:.1} s; {} contained panics in third-party decoders",
        start.elapsed().as_secs_f64(),
        DECODER_PANICS.load(Ordering::SeqCst)
    );
    assert!(
        err > 1000 && ok > 100,
        "mutations should both break and spare files: {ok} ok, {err} errors"
    );
    assert_eq!(
        PANICS.load(Ordering::SeqCst),
        0,
        "the loader panicked (caught or not) on corrupted input"
    );
}
