//! The key-script parser on arbitrary text: it must return keys or an error
//! naming the place, never panic; every key it returns prints as a name
//! that parses back to the same key.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    match nudge::script::parse_keys(text, "fuzz.keys") {
        Ok(keys) => {
            for key in keys {
                let printed = key.to_string();
                let back = nudge::script::parse_keys(&printed, "printed.keys");
                assert!(matches!(back.as_deref(), Ok([k]) if *k == key), "{printed:?} does not parse back to {key:?}");
            }
        }
        Err(e) => assert!(e.to_string().starts_with("fuzz.keys:"), "{e}"),
    }
});
