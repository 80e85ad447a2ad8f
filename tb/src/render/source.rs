//! `render --firmware FILE.s`: a program read from a file instead of the generated one,
//! checked against the data image of the render's scene and options.

use anyhow::{anyhow, Result};
use firmware::asm;
use firmware::tracer::{data, mem, Firmware};
use rtl::rc::Datapath;

/// The lines of a generated firmware's header that name the options it
/// was generated for (size, ways, depth, datapath, format; traversal and
/// BSP): a program written for other options reads another data image.
fn header(source: &str) -> Vec<&str> {
    source
        .lines()
        .take_while(|l| l.starts_with(';'))
        .skip(1)
        .take(2)
        .collect()
}

/// The `.datapath` a firmware source declares (16 without the directive).
pub(crate) fn source_datapath(source: &str) -> Datapath {
    source
        .lines()
        .map(|l| l.split(';').next().unwrap_or("").trim())
        .find_map(|l| l.strip_prefix(".datapath"))
        .and_then(|v| v.trim().parse::<u32>().ok())
        .and_then(Datapath::from_bits)
        .unwrap_or(Datapath::W16)
}

/// `render --firmware FILE.s`: `fw` (generated for the same scene and
/// options: its data image, FB and streamed, is kept) with its program
/// replaced by the one assembled from `text`. Refused with the file's name
/// when it does not assemble (file:line:col), was generated for other
/// options (its header or the data image's addresses differ), or does not
/// fit below the data the host loads.
pub(crate) fn firmware_from_source(mut fw: Firmware, text: &str, name: &str) -> Result<Firmware> {
    let img = asm::assemble(text, name).map_err(|e| anyhow!("{e}"))?;
    let (want, got) = (header(&fw.source), header(text));
    if want != got {
        fn line<'a>(v: &[&'a str], k: usize) -> &'a str {
            v.get(k).copied().unwrap_or("(no header line)")
        }
        let k = (0..2)
            .find(|&k| line(&want, k) != line(&got, k))
            .unwrap_or(0);
        anyhow::bail!(
            "{name}:{}: the firmware was generated for `{}`; these options give `{}` (render it with the options it was emitted with)",
            k + 2,
            line(&got, k).trim_start_matches("; "),
            line(&want, k).trim_start_matches("; ")
        );
    }
    let gen = asm::assemble(&fw.source, "generated")
        .map_err(|e| anyhow!("internal: the generated firmware does not assemble:\n{e}"))?;
    for data::Label(sym) in data::IMAGE_SYMBOLS {
        if gen.symbol(sym) != img.symbol(sym) {
            anyhow::bail!(
                "{name}: {sym} is {:?} in the file and {:?} in the data image of these options: the file was generated for another scene or options",
                img.symbol(sym),
                gen.symbol(sym)
            );
        }
    }
    // The program must end below the first data the host loads.
    for seg in &img.segments {
        let end = seg.addr as u64 + seg.data.len() as u64;
        if seg.addr < mem::FB_IMAGE && end > mem::FB_IMAGE as u64 {
            anyhow::bail!(
                "{name}: the program's segment at 0x{:x} ends at 0x{end:x}, past 0x{:x} where the host loads the FB image (the context memory holds 8192 words: 0x{:x}..0x{:x})",
                seg.addr,
                mem::FB_IMAGE,
                mem::CTX_BASE,
                mem::CTX_BASE + 4 * 8192
            );
        }
    }
    // The kernels as the file lays them out: `k_NAME` .. `k_NAME_end`.
    let mut kernels: Vec<(i64, String, usize)> = img
        .symbols
        .iter()
        .filter(|(n, v)| n.starts_with("k_") && !n.ends_with("_end") && **v >= mem::CTX_BASE as i64)
        .filter_map(|(n, v)| {
            let e = img.symbol(&format!("{n}_end"))?;
            Some((*v, n.clone(), ((e - v) / 4).max(0) as usize))
        })
        .collect();
    kernels.sort();
    fw.context_words = kernels.iter().map(|k| k.2).sum();
    fw.kernels = kernels.into_iter().map(|(_, n, l)| (n, l)).collect();
    fw.source = text.to_string();
    Ok(fw)
}
