//! What a render's result depends on besides its arguments: the scene,
//! timing and firmware it read and the build that ran it, each as a
//! SHA-256 digest. `render --skip-done`, a resumed sweep and `sweep
//! --merge` take a finished render only when its arguments and these are
//! unchanged, and say so when one changed.

use sha2::{Digest, Sha256};

/// The SHA-256 of `bytes`, in hex.
pub(crate) fn digest(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// A scene's content, wherever its file is (the name left out: a plan's
/// folder may move between its renders and its merge).
pub(crate) fn scene_digest(scene: &firmware::scene::Scene) -> String {
    let mut s = scene.clone();
    s.source.clear();
    digest(format!("{s:?}").as_bytes())
}

/// A chip timing's values.
pub(crate) fn timing_digest(t: &rtl::Timing) -> String {
    digest(format!("{t:?}").as_bytes())
}

/// This build: the SHA-256 of the sources its results depend on (the
/// chip, the firmware generator, this crate and the lock file; `build.rs`),
/// so a render made by another build is not taken for one of this build.
pub(crate) fn build_digest() -> &'static str {
    env!("MORPHOSYS_SOURCE_DIGEST")
}

/// The `inputs` a render's JSON records.
pub fn inputs(
    scene: &firmware::scene::Scene,
    timing: &rtl::Timing,
    firmware_text: Option<&str>,
) -> serde_json::Value {
    serde_json::json!({
        "scene": scene_digest(scene),
        "timing": timing_digest(timing),
        "firmware": firmware_text.map(|t| digest(t.as_bytes())),
        "build": build_digest(),
    })
}

/// Which of the recorded `inputs` differ from `now`, in words ("the
/// scene, the build"); None when all agree.
pub fn changed(recorded: &serde_json::Value, now: &serde_json::Value) -> Option<String> {
    let names = [
        ("scene", "the scene"),
        ("timing", "the timing file"),
        ("firmware", "the firmware"),
        ("build", "this build"),
    ];
    let differ: Vec<&str> = names
        .iter()
        .filter(|(k, _)| recorded.get(k) != now.get(k))
        .map(|(_, w)| *w)
        .collect();
    (!differ.is_empty()).then(|| differ.join(", "))
}
