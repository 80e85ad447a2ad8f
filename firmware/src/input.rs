//! Every input file is read through here, bounded: a regular file, a
//! device (`/dev/zero`), a FIFO fed without end or a descriptor alike stop
//! at [`MAX_INPUT_BYTES`] with an error, never when memory runs out.

use std::io::Read;
use std::path::Path;

/// The most any input (scene, program, timing file, plan, hit map) may
/// hold.
pub const MAX_INPUT_BYTES: u64 = 64 << 20;

/// The bytes of `path`, at most `MAX_INPUT_BYTES` of them.
pub fn read(path: &Path) -> std::io::Result<Vec<u8>> {
    let f = std::fs::File::open(path)?;
    if f.metadata().is_ok_and(|m| m.is_dir()) {
        return Err(std::io::Error::other("is a folder"));
    }
    let mut bytes = Vec::new();
    f.take(MAX_INPUT_BYTES + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > MAX_INPUT_BYTES {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!(
                "more than {} MB (inputs are read up to {} MB)",
                MAX_INPUT_BYTES >> 20,
                MAX_INPUT_BYTES >> 20
            ),
        ));
    }
    Ok(bytes)
}

/// [`read`], as UTF-8 text.
pub fn read_to_string(path: &Path) -> std::io::Result<String> {
    String::from_utf8(read(path)?).map_err(|e| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("not UTF-8 text (byte {})", e.utf8_error().valid_up_to()),
        )
    })
}

#[cfg(test)]
mod tests {
    #[test]
    fn an_endless_device_stops_at_the_limit() {
        let p = std::path::Path::new("/dev/zero");
        if p.exists() {
            let e = super::read(p).unwrap_err();
            assert!(e.to_string().contains("more than 64 MB"), "{e}");
        }
    }
}
