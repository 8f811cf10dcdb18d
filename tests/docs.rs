//! Everything the README, the docs and the code cite exists in this
//! repository: relative links, and paths under `docs/`, `scenes/`,
//! `tests/`, `src/` and `fuzz/` written in backquotes or links.

use std::path::{Path, PathBuf};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// Candidate paths cited in `text`: Markdown link targets and words that
/// start with one of the repository's top-level folders.
fn cited(text: &str, relative_to: &Path) -> Vec<(String, PathBuf)> {
    let mut out = Vec::new();
    // Markdown links: ](target)
    for part in text.split("](").skip(1) {
        let target = part.split(')').next().unwrap_or("");
        let target = target.split('#').next().unwrap_or("");
        if target.is_empty() || target.contains("://") || target.starts_with("mailto:") {
            continue;
        }
        out.push((target.to_string(), relative_to.join(target)));
    }
    // Paths from the root: docs/x.md, scenes/eggs.toml, tests/..., src/...
    for word in text.split(|c: char| c.is_whitespace() || "`'\"()[],;".contains(c)) {
        // `file.toml:8:8` cites the file.
        let word = word.split(':').next().unwrap_or("").trim_end_matches('.');
        let stem = Path::new(word)
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("");
        let placeholder = !stem.is_empty() && stem.chars().all(|c| c.is_ascii_uppercase());
        let rooted = ["docs/", "scenes/", "tests/", "src/", "fuzz/"]
            .iter()
            .any(|p| word.starts_with(p));
        // Globs, placeholders and generated outputs are not files.
        let concrete = !word.contains(['*', '<', '>', '{', '$']) && !word.ends_with('/');
        if rooted && concrete && !placeholder && word.contains('.') {
            out.push((word.to_string(), Path::new(ROOT).join(word)));
        }
    }
    out.sort();
    out.dedup();
    out
}

fn missing_in(file: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    let dir = file.parent().unwrap_or(Path::new(ROOT));
    cited(&text, dir)
        .into_iter()
        .filter(|(_, p)| !p.exists())
        .map(|(w, _)| format!("{}: {w}", file.display()))
        .collect()
}

fn files(dir: &Path, ext: &str, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).expect("readable").flatten() {
        let p = e.path();
        if p.is_dir() {
            files(&p, ext, out);
        } else if p.extension().is_some_and(|x| x == ext) {
            out.push(p);
        }
    }
}

#[test]
fn everything_the_readme_and_the_docs_cite_exists() {
    let mut docs = vec![Path::new(ROOT).join("README.md")];
    files(&Path::new(ROOT).join("docs"), "md", &mut docs);
    assert!(docs.len() >= 4, "{docs:?}");
    let missing: Vec<String> = docs.iter().flat_map(|d| missing_in(d)).collect();
    assert!(
        missing.is_empty(),
        "cited but missing:\n{}",
        missing.join("\n")
    );
}

#[test]
fn every_docs_path_the_code_cites_exists() {
    let mut sources = Vec::new();
    files(&Path::new(ROOT).join("src"), "rs", &mut sources);
    let mut missing = Vec::new();
    for f in &sources {
        let text = std::fs::read_to_string(f).expect("source");
        for (w, p) in cited(&text, Path::new(ROOT)) {
            if w.starts_with("docs/") && !p.exists() {
                missing.push(format!("{}: {w}", f.display()));
            }
        }
    }
    assert!(
        missing.is_empty(),
        "cited but missing:\n{}",
        missing.join("\n")
    );
}

/// The check itself finds a broken citation.
#[test]
fn a_missing_citation_is_found() {
    let text = "see [the guide](docs/no-such-guide.md) and `scenes/nope.toml`";
    let found: Vec<String> = cited(text, Path::new(ROOT))
        .into_iter()
        .filter(|(_, p)| !p.exists())
        .map(|(w, _)| w)
        .collect();
    assert_eq!(found, ["docs/no-such-guide.md", "scenes/nope.toml"]);
}

/// Every `docs/design.md §N` the code cites names a section of it.
#[test]
fn every_design_section_the_code_cites_exists() {
    let design = std::fs::read_to_string(Path::new(ROOT).join("docs/design.md")).expect("design");
    let mut sources = Vec::new();
    files(&Path::new(ROOT).join("src"), "rs", &mut sources);
    files(&Path::new(ROOT).join("tests"), "rs", &mut sources);
    let mut cited_sections = 0;
    let mut missing = Vec::new();
    for f in &sources {
        let text = std::fs::read_to_string(f).expect("source");
        for part in text.split("docs/design.md §").skip(1) {
            // `§3–§5` cites 3 to 5.
            let numbers: Vec<u32> = part
                .split(|c: char| !(c.is_ascii_digit() || c == '–' || c == '§'))
                .next()
                .unwrap_or("")
                .split(['–', '§'])
                .filter_map(|n| n.parse().ok())
                .collect();
            for n in numbers {
                cited_sections += 1;
                if !design.contains(&format!("\n## {n}. ")) {
                    missing.push(format!("{}: §{n}", f.display()));
                }
            }
        }
    }
    assert!(cited_sections >= 10, "{cited_sections} citations");
    assert!(
        missing.is_empty(),
        "sections cited but missing:\n{}",
        missing.join("\n")
    );
}
