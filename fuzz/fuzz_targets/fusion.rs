//! libFuzzer target: the bytes are the draws of one `host_tests::fuzz::fusion`
//! case, checked against its oracles (a broken oracle panics: a crash).
#![no_main]

use host_tests::fuzz::{Source, Target};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    Target::Fusion.run(&mut Source::bytes(data));
});
