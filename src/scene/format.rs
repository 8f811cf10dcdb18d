//! The TOML scene format: parsing, validation with located messages, and saving.
//! (Being written: see the scene-format task.)
use super::model::Scene;
use std::path::Path;

/// A scene that could not be loaded.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SceneError {
    #[error("{0}")]
    Invalid(String),
}

/// Load and validate a scene file.
pub fn load(path: &Path) -> Result<Scene, SceneError> {
    let text = std::fs::read_to_string(path).map_err(|e| SceneError::Invalid(e.to_string()))?;
    load_str(&text, &path.display().to_string())
}

/// Parse and validate scene text; `origin` names the file in messages.
pub fn load_str(_text: &str, _origin: &str) -> Result<Scene, SceneError> {
    Err(SceneError::Invalid("not yet".into()))
}

/// Serialise a scene to TOML text that loads back to the same motion bit-for-bit.
pub fn to_toml(_scene: &Scene) -> String {
    String::new()
}

/// Write a scene atomically (temporary file, then rename).
pub fn save(scene: &Scene, path: &Path) -> std::io::Result<()> {
    let tmp = path.with_extension("toml.tmp");
    std::fs::write(&tmp, to_toml(scene))?;
    std::fs::rename(tmp, path)
}
