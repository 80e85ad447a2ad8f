//! The FB streams before the object records: the camera's eye stream,
//! the post-pass and refraction streams, the lights and their Phong
//! terms; and the scene's coordinate format ([`fit_frac`]) and the lights'
//! scale shifts ([`light_shift`]).

use crate::scene::{Scene, Vec3};

use super::super::shading::phong_exponent;
use super::super::Options;
use super::{fit_shift_w, W};
/// The scene's distinct materials, and per scene material its index among
/// them (materials equal in every field are one).
pub(super) fn distinct_materials(scene: &Scene) -> (Vec<usize>, Vec<crate::scene::Material>) {
    let key = |m: &crate::scene::Material| {
        [
            m.color.x, m.color.y, m.color.z, m.kd, m.ks, m.shine, m.t, m.ior,
        ]
        .map(f64::to_bits)
    };
    let mut seen = std::collections::HashMap::new();
    let mut mats = Vec::new();
    let of = scene
        .materials
        .iter()
        .map(|m| {
            *seen.entry(key(m)).or_insert_with(|| {
                mats.push(m.clone());
                mats.len() - 1
            })
        })
        .collect();
    (of, mats)
}

/// Largest absolute coordinate of the eye and of every object's bounds.
pub(super) fn extent(scene: &Scene) -> f64 {
    let mut m: f64 = scene.camera.from.max_abs();
    for o in &scene.objects {
        let b = o.shape.bounds();
        m = m.max(b.min.max_abs()).max(b.max.max_abs());
    }
    m
}

/// The tracer's coordinate format: the finest `Qm.n` in which every object
/// and the eye fit with two guard bits (so that differences of points and
/// distances across the scene fit); never coarser than the scene
/// compiler's format (whose BSP planes are snapped to its LSB, hence exact
/// in a finer one). Lights do not take part: only their difference to a
/// point of the scene is ever formed, at a coarser scale when needed
/// ([`light_shift`]).
pub fn fit_frac(scene: &Scene, compiler_frac: u32, guard_bits: u32) -> u32 {
    let m = extent(scene);
    (compiler_frac..=14)
        .rev()
        .find(|&n| m * (guard_bits as f64).exp2() < ((15 - n) as f64).exp2() * 0.999)
        .unwrap_or(compiler_frac)
}

/// Scale of a light in the shadow-ray kernel: the smallest `k` for which
/// `(light - P) / 2^k` fits the format `frac` for every point `P` of the
/// scene (`|P| <= m`, [`extent`]). The light is stored divided by `2^k`
/// and the kernel forms `light / 2^k - P / 2^k`; its direction is all a
/// shadow ray needs. A light with `k > 0` lies outside the box `[-m, m]^3`
/// that holds every object (`l + m >= 2^(15 - frac) > 2 m`), so no object
/// lies beyond it along the shadow ray and the ray's segment may end at
/// "no hit" (32767) instead of at the light.
pub fn light_shift(position: Vec3, m: f64, frac: u32) -> Option<u32> {
    light_shift_w(position, m, frac, 0)
}

/// [`light_shift`] for words with `x` extra bits (`frac` includes them).
pub fn light_shift_w(position: Vec3, m: f64, frac: u32, x: u32) -> Option<u32> {
    let range = ((15 + x - frac) as f64).exp2() * 0.999;
    let l = position.max_abs();
    (0..=15u32).find(|&k| (l + m) < range * (k as f64).exp2())
}

/// The eye stream (`D(i, j) = A + i B + j C`): its FB address and the
/// scale shift `KD` of B and C.
pub(super) fn camera(
    w: &mut W,
    scene: &Scene,
    opt: &Options,
    fine_normals: bool,
) -> Result<(usize, u32), String> {
    let xb = w.x;
    let c = &scene.camera;
    let (wd, hd) = (opt.width.max(1), opt.height.max(1));
    let ww = (c.at - c.from).normalized();
    let uu = ww.cross(c.up).normalized();
    let vv = uu.cross(ww);
    let half = (c.angle.to_radians() / 2.0).tan();
    let (ax, ay) = if wd >= hd {
        (wd as f64 / hd as f64, 1.0)
    } else {
        (1.0, hd as f64 / wd as f64)
    };
    let mut a = ww;
    let mut b = Vec3::ZERO;
    let mut cc = Vec3::ZERO;
    if wd > 1 {
        a = a - uu * (ax * half);
        b = uu * (ax * half * 2.0 / (wd - 1) as f64);
    }
    if hd > 1 {
        a = a + vv * (ay * half);
        cc = vv * (-ay * half * 2.0 / (hd - 1) as f64);
    }
    let max_bc = b.max_abs().max(cc.max_abs());
    let kd = fit_shift_w(max_bc, 28 + xb, xb).max(13 + xb);
    let corner_far = a + b * (wd - 1) as f64 + cc * (hd - 1) as f64;
    if a.max_abs() >= 3.9 || corner_far.max_abs() >= 3.9 {
        let aspect = ax.max(ay);
        let long = 2.0 * (aspect * half).atan().to_degrees();
        return Err(if aspect > 1.0 {
            format!(
                "a {wd}x{hd} image ({aspect:.1}:1) with the camera angle {} across its shorter side spans {long:.0} degrees across its longer: too wide for the chip's Q2.13 eye-ray directions (at most about 150 degrees); a squarer image or a narrower angle fits",
                c.angle
            )
        } else {
            format!(
                "camera angle {} too wide for the chip's Q2.13 eye-ray directions (at most about 150 degrees)",
                c.angle
            )
        });
    }
    let eye = w.fb.len();
    w.raw(0);
    w.raw(0);
    w.point(c.from);
    if super::super::positions::precise_eye(opt, fine_normals) {
        local_camera(w, c.from, [a, b, cc], kd);
        return Ok((eye, kd));
    }
    for k in 0..3 {
        w.push(a.axis(k) * w.one() / 2.0);
        w.push(b.axis(k) * (kd as f64).exp2());
        w.push(cc.axis(k) * (kd as f64).exp2());
    }
    Ok((eye, kd))
}

/// The rest of the camera stream for local positions
/// ([`super::super::positions::eye`]): the eye's remainder (2^-14 LSB),
/// then per axis the pixel steps' remainders `B_L`, `C_L` (2^-16 of
/// their LSB), `A` in Q2.13 and its remainder `A_L` (2^-KD), `B`, `C`
/// (2^-KD): the eye rays' directions to 2^-KD before normalising.
fn local_camera(w: &mut W, from: Vec3, [a, b, cc]: [Vec3; 3], kd: u32) {
    let s = w.s;
    for x in from.to_array() {
        w.push((x * s - w.sat(x * s) as f64) * 16384.0);
    }
    let k2 = (kd as f64).exp2();
    for k in 0..3 {
        let (ah, bh, ch) = (
            w.sat(a.axis(k) * 8192.0) as f64,
            w.sat(b.axis(k) * k2) as f64,
            w.sat(cc.axis(k) * k2) as f64,
        );
        w.push((b.axis(k) * k2 - bh) * 65536.0);
        w.push((cc.axis(k) * k2 - ch) * 65536.0);
        w.push(ah);
        w.push(a.axis(k) * k2 - ah * (kd as f64 - 13.0).exp2());
        w.push(bh);
        w.push(ch);
    }
}

/// The light and shading streams: per light its position (with a scale
/// shift where some light is far), then per light, per material its Phong
/// terms. Returns their FB addresses and whether lights carry a shift.
pub(super) fn lights(
    w: &mut W,
    scene: &Scene,
    mats: &[crate::scene::Material],
    frac: u32,
    xb: u32,
    skip_dull: bool,
) -> Result<(Vec<usize>, Vec<usize>, bool), String> {
    let nl = scene.lights.len().max(1) as f64;
    let m = extent(scene);
    let mut shifts = Vec::new();
    for l in &scene.lights {
        shifts.push(light_shift_w(l.position, m, frac, xb).ok_or_else(|| {
            format!(
                "light at {:?} too far from the scene for the format's differences",
                l.position.to_array()
            )
        })?);
    }
    let light_shifted = shifts.iter().any(|&k| k > 0);
    let mut lights = Vec::new();
    for (l, &k) in scene.lights.iter().zip(&shifts) {
        lights.push(w.fb.len());
        if light_shifted {
            w.raw(k as i64);
        }
        w.point(l.position * (-(k as f64)).exp2());
    }
    let mut shades = Vec::new();
    for l in &scene.lights {
        shades.push(w.fb.len());
        let lc = l.color.unwrap_or(Vec3::ONE * (1.0 / nl.sqrt()));
        for (i, mt) in mats.iter().enumerate() {
            w.raw(i as i64);
            let (_, f) = phong_exponent(mt, skip_dull);
            if f > 0.0 {
                w.push(f * w.one());
                w.push((1.0 - f) * w.one());
            }
            // Per channel: kd c lc, then ks lc (the kernel's read order).
            let k = mt.color.mul_elem(lc) * mt.kd;
            let sp = lc * mt.ks;
            for c in 0..3 {
                w.col(k.axis(c));
                w.col(sp.axis(c));
            }
        }
    }
    Ok((lights, shades, light_shifted))
}

/// The post-pass stream (background, then `id, ks` per material) and,
/// where the scene refracts, the refraction stream (`id, T, 1/ior, ior`
/// per transmitting material, read by `k_tset`): their FB addresses and
/// the transmitting materials.
pub(super) fn post_streams(
    w: &mut W,
    scene: &Scene,
    mats: &[crate::scene::Material],
    refract: bool,
) -> (usize, usize, usize) {
    // Post: background, (id, ks) per material.
    let post = w.fb.len();
    for x in scene.background.to_array() {
        w.col(x);
    }
    for (i, mt) in mats.iter().enumerate() {
        w.raw(i as i64);
        w.col(mt.ks);
    }
    // Refraction: per transmitting material `id, T, 1/ior, ior` (the
    // stream of `k_tset`), only when a refracting object uses one.
    let transmit = w.fb.len();
    let mut transmit_materials = 0;
    if refract {
        for (i, mt) in mats.iter().enumerate().filter(|(_, m)| m.t > 0.0) {
            w.raw(i as i64);
            w.col(mt.t);
            w.col(1.0 / mt.ior);
            w.col(mt.ior);
            transmit_materials += 1;
        }
    }
    (post, transmit, transmit_materials)
}
