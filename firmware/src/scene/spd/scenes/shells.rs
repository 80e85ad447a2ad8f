//! shells.c: Pickover's sea shell of spheres.

use std::f64::consts::PI;

use super::super::spdlib::*;

pub(crate) fn shells(lib: &mut Lib, size: u32) {
    let fgamma = 1.0;
    let alpha = 0.0;
    let beta = -2.0;
    let a = 0.15;
    let k = 1.0;
    lib.background([0.078, 0.361, 0.753]);
    lib.viewpoint(
        [-6.0, -60.0, 35.0],
        [0.0, 8.0, -15.0],
        [0.0, 0.0, 1.0],
        45.0,
        1.0,
        0.5,
        512,
        512,
    );
    lib.light([-100.0, -100.0, 100.0, 1.0]);
    lib.color([1.0, 0.8, 0.4], 0.0, 0.8, 0.2, 0.5, 10.0, 0.0, 1.0);
    let steps = (180.0 * 2.0f64.powf(size as f64)) as i64;
    for i in (-steps * 2 / 3)..=(steps / 3) {
        let angle = 3.0 * 6.0 * PI * i as f64 / steps as f64;
        let r = k * (a * angle).exp();
        let z = if alpha > 0.0 { alpha * angle } else { beta * r };
        lib.sphere([r * angle.sin(), r * angle.cos(), z, r / fgamma]);
    }
}
