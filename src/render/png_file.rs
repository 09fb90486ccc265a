//! PNG files: an RGB image encoded with fixed settings (no time stamp, no text chunk), so the
//! same pixels give the same bytes; written under a temporary name and renamed, so a viewer or
//! ffmpeg never reads half a picture. (Not fsynced: after a power cut a picture may be empty,
//! which rendering again mends; a sync per frame would double the time of `--all`.)

use super::raster::Image;
use std::io::{BufWriter, Write};
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

/// Writes `bytes` to `path` through a temporary file beside it.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let name = path.file_name().unwrap_or_default().to_string_lossy();
    let private = path.with_file_name(format!(".{name}.tmp-{}", std::process::id()));
    let written = (|| {
        let mut file = BufWriter::new(std::fs::File::create(&private)?);
        file.write_all(bytes)?;
        file.flush()
    })();
    match written.and_then(|()| std::fs::rename(&private, path)) {
        Ok(()) => Ok(()),
        Err(e) => {
            let _ = std::fs::remove_file(&private);
            Err(e)
        }
    }
}

/// True when the file at `path` starts as a PNG does.
pub fn is_png(path: &Path) -> bool {
    use std::io::Read;
    let mut head = [0u8; 8];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut head))
        .is_ok_and(|()| head == SIGNATURE)
}
