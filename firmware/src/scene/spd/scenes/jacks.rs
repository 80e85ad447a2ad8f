//! jacks.c: recursive jacks (Alexander Enzmann).

use std::f64::consts::PI;

use super::super::spdlib::*;
use super::super::{X_AXIS, Y_AXIS};
use super::LSCALE_NFF;

pub(crate) fn jacks(lib: &mut Lib, size: u32) {
    pub(super) fn make_jack_obj(lib: &mut Lib) {
        lib.tx_push();
        lib.tx_scale([0.75, 0.75, 0.75]);
        lib.cylcone([-1.0, 0.0, 0.0, 0.1], [1.0, 0.0, 0.0, 0.1]);
        lib.cylcone([0.0, -1.0, 0.0, 0.1], [0.0, 1.0, 0.0, 0.1]);
        lib.cylcone([0.0, 0.0, -1.0, 0.1], [0.0, 0.0, 1.0, 0.1]);
        lib.sphere([1.0, 0.0, 0.0, 0.2]);
        lib.sphere([0.0, 1.0, 0.0, 0.2]);
        lib.sphere([0.0, 0.0, 1.0, 0.2]);
        lib.sphere([-1.0, 0.0, 0.0, 0.2]);
        lib.sphere([0.0, -1.0, 0.0, 0.2]);
        lib.sphere([0.0, 0.0, -1.0, 0.2]);
        lib.tx_pop();
    }

    pub(super) fn make_rec_jack(lib: &mut Lib, depth: u32, max_depth: u32) {
        make_jack_obj(lib);
        if depth < max_depth {
            for i in [-0.5, 0.5] {
                for j in [-0.5, 0.5] {
                    for k in [-0.5, 0.5] {
                        lib.tx_push();
                        lib.tx_translate([i, j, k]);
                        lib.tx_scale([0.5, 0.5, 0.5]);
                        make_rec_jack(lib, depth + 1, max_depth);
                        lib.tx_pop();
                    }
                }
            }
        }
    }

    lib.background([0.2, 0.05, 0.2]);
    lib.viewpoint(
        [0.0, 0.0, -8.0],
        [0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        25.0,
        1.0,
        0.001,
        256,
        256,
    );
    lib.light([-10.0, 3.0, -20.0, LSCALE_NFF]);
    lib.tx_push();
    lib.tx_rotate(X_AXIS, -30.0 * PI / 180.0);
    lib.tx_rotate(Y_AXIS, -20.0 * PI / 180.0);
    lib.color([0.737, 0.561, 0.561], 0.1, 0.7, 0.7, 0.4, 20.0, 0.0, 1.0);
    make_rec_jack(lib, 1, size);
    lib.tx_pop();
}
