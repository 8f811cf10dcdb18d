//! The scene parser on arbitrary text: it must return a scene or a located
//! error, never panic, and a scene it accepts must save and load back.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    if let Ok(scene) = nudge::scene::load_str(text, "fuzz.toml") {
        // Accepted scenes are valid: every number finite, and they survive
        // a save/load round trip.
        let saved = nudge::scene::to_toml(&scene);
        let back = nudge::scene::load_str(&saved, "fuzz-saved.toml");
        assert!(back.is_ok(), "a saved scene does not load back: {:?}\n{saved}", back.err());
    }
});
