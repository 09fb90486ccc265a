//! PNG files: an RGB image encoded with fixed settings (no time stamp, no text chunk), so the
//! same pixels give the same bytes; written by `io::replace_file` (a temporary name, then a
//! rename), so a viewer or ffmpeg never reads half a picture. (Not fsynced: after a power cut a
//! picture may be empty, which rendering again mends; a sync per frame would double the time of
//! `--all`.)

use super::raster::Image;
use std::path::Path;

/// The eight bytes every PNG file starts with.
pub const SIGNATURE: [u8; 8] = [0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a];

/// The PNG encoding of `image`.
pub fn encode(image: &Image) -> Result<Vec<u8>, png::EncodingError> {
    let mut bytes = Vec::new();
    let mut encoder = png::Encoder::new(&mut bytes, image.width, image.height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_compression(png::Compression::Default);
    let mut writer = encoder.write_header()?;
    writer.write_image_data(&image.rgb)?;
    writer.finish()?;
    Ok(bytes)
}

/// True when the file at `path` starts as a PNG does.
pub fn is_png(path: &Path) -> bool {
    use std::io::Read;
    let mut head = [0u8; 8];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut head))
        .is_ok_and(|()| head == SIGNATURE)
}
