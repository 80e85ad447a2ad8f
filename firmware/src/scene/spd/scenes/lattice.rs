//! lattice.c: spheres joined by cylinders in a cubic lattice (Antonio Costa).

use super::super::spdlib::*;

pub(crate) fn lattice(lib: &mut Lib, size: u32) {
    const RADIUS1: f64 = 1.0 / 4.0;
    const RADIUS2: f64 = 1.0 / 16.0;
    let sf = size as f64;
    let inv_factor = 1.0 / sf;
    let radius1 = RADIUS1 / sf;
    let radius2 = RADIUS2 / sf;
    let delta = (radius1 * (1.0 - (RADIUS2 / RADIUS1).sqrt())) * 0.99;
    lib.background([0.078, 0.361, 0.753]);
    let half = (size >> 1) as f64;
    let from = [
        (half + 0.5) * inv_factor,
        1.0,
        1.0 - 1.0 / (size << 1) as f64,
    ];
    let at = [
        (half + 0.5) * inv_factor,
        -1.0,
        -1.0 - 1.0 / (size << 1) as f64,
    ];
    lib.viewpoint(from, at, [0.2, 1.0, 0.0], 60.0, 1.0, 0.0, 512, 512);
    let lscale = 1.0 / 6.0f64.sqrt();
    lib.light([2.0, 0.5, 0.5, lscale]);
    lib.light([-1.0, 0.5, 0.5, lscale]);
    lib.light([0.5, 2.0, 0.5, lscale]);
    lib.light([0.5, -1.0, 0.5, lscale]);
    lib.light([0.5, 0.5, 2.0, lscale]);
    lib.light([0.5, 0.5, -1.0, lscale]);
    for x in 0..=size {
        let x0 = x as f64 / sf;
        for y in 0..=size {
            let y0 = y as f64 / sf;
            for z in 0..=size {
                let z0 = z as f64 / sf;
                lib.color([0.9, 0.9, 0.9], 0.0, 0.5, 0.5, 0.5, 37.0, 0.0, 0.0);
                lib.sphere([x0, y0, z0, radius1]);
                if x != size {
                    lib.color([0.9, 0.1, 0.1], 0.1, 0.99, 0.0, 0.0, 0.0, 0.0, 0.0);
                    lib.cylcone(
                        [x0 + delta, y0, z0, radius2],
                        [x0 + inv_factor - delta, y0, z0, radius2],
                    );
                }
                if y != size {
                    lib.color([0.1, 0.9, 0.1], 0.1, 0.99, 0.0, 0.0, 0.0, 0.0, 0.0);
                    lib.cylcone(
                        [x0, y0 + delta, z0, radius2],
                        [x0, y0 + inv_factor - delta, z0, radius2],
                    );
                }
                if z != size {
                    lib.color([0.1, 0.1, 0.9], 0.1, 0.99, 0.0, 0.0, 0.0, 0.0, 0.0);
                    lib.cylcone(
                        [x0, y0, z0 + delta, radius2],
                        [x0, y0, z0 + inv_factor - delta, radius2],
                    );
                }
            }
        }
    }
}
