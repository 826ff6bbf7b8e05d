//! Proptest strategies shared by the cam-law property files (`props_cam_law`, `props_cam_law_fit`).

use proptest::prelude::*;

/// Seven coefficients, each exactly 0 with probability ~1/3, else in [0.02, 1]; both pulses
/// non-empty (an empty pulse is repaired by giving its middle segment a length).
pub fn coefficients() -> impl Strategy<Value = [f64; 7]> {
    proptest::array::uniform7(prop_oneof![1 => Just(0.0), 2 => 0.02f64..1.0]).prop_map(|mut c| {
        if c[0] + c[1] + c[2] <= 0.0 {
            c[1] = 0.3;
        }
        if c[4] + c[5] + c[6] <= 0.0 {
            c[5] = 0.3;
        }
        c
    })
}
