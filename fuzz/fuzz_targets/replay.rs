//! libFuzzer target: the bytes are a JSON Lines input of the replay tool,
//! checked by `host_tests::fuzz::replay::check_input` (a broken oracle
//! panics: a crash).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    host_tests::fuzz::replay::check_input(data);
});
