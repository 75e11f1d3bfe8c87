//! Helpers shared by the offscreen rendering tests.

use dupin_render::{OffscreenImage, RenderError};
use std::path::{Path, PathBuf};

/// Image size of every rendering test.
pub const W: u32 = 320;
pub const H: u32 = 240;

/// The image, or a panic that says how to get a software rasteriser.
pub fn expect_image(r: Result<OffscreenImage, RenderError>) -> OffscreenImage {
    r.unwrap_or_else(|e| {
        panic!("offscreen rendering failed: {e}. Install a Vulkan driver (apt-get install mesa-vulkan-drivers) or run `cargo xtask test`, which does.")
    })
}

/// `target/render-tests`, where every test image is written.
fn out_dir() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../target/render-tests");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Writes `img` as `target/render-tests/<name>` (PNG) and returns its path.
pub fn save(img: &OffscreenImage, name: &str) -> PathBuf {
    let path = out_dir().join(name);
    image::save_buffer(
        &path,
        &img.rgba,
        img.width,
        img.height,
        image::ColorType::Rgba8,
    )
    .unwrap();
    path
}

/// The committed reference image `tests/reference/<name>` (W x H RGBA bytes) and its path;
/// with `DUPIN_BLESS` set, the freshly saved `actual` replaces it first.
pub fn reference_image(name: &str, actual: &Path) -> (Vec<u8>, PathBuf) {
    let reference = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/reference")
        .join(name);
    if std::env::var_os("DUPIN_BLESS").is_some() {
        std::fs::copy(actual, &reference).unwrap();
    }
    let want = image::open(&reference)
        .unwrap_or_else(|e| {
            panic!(
                "{}: {e}; run with DUPIN_BLESS=1 to create it",
                reference.display()
            )
        })
        .to_rgba8();
    assert_eq!((want.width(), want.height()), (W, H));
    (want.into_raw(), reference)
}
