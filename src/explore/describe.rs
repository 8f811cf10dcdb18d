//! What an alternative's collisions change, in words: the contacts that
//! shape the edit (the events of the signature), named by body, party, part
//! and feature, compared with the current motion's.

use crate::report::party_name;
use crate::scene::Scene;
use crate::sim::{Party, Trajectory};
use std::collections::BTreeMap;

/// One contact of a motion, as the description names it.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub struct Contact {
    /// The body that collides, e.g. `egg1`.
    pub body: String,
    /// What it hits, e.g. `bucket_b part 2`.
    pub other: String,
    /// The feature of `other` it touches, e.g. `face f2-3-9-10`; empty for
    /// a ball, a plane or a parabola (one feature only), `flat` for a
    /// face-to-face contact patch.
    pub feature: String,
    /// `rests` or `slides` when the contact ends the bounce that way.
    pub ending: String,
}

impl Contact {
    /// The party, with its place: `hill at face f2-3-9-10`.
    fn target(&self) -> String {
        match self.feature.as_str() {
            "" => self.other.clone(),
            "flat" => format!("{} flat", self.other),
            f => format!("{} at {f}", self.other),
        }
    }

    /// The contact in words: `ball hits hill at face f1-2-8-9`.
    pub fn words(&self) -> String {
        format!("{} {}", self.body, self.what())
    }

    /// The verb phrase: `hits hill at face f1-2-8-9 and rests`.
    fn what(&self) -> String {
        let ending = match self.ending.as_str() {
            "" => String::new(),
            e => format!(" and {e}"),
        };
        format!("hits {}{ending}", self.target())
    }
}

/// The features a key's side names, in words (`f1-2` a face, `e3-4` an
/// edge, `v5` a vertex; a patch is `flat`).
fn feature_words(side: &str) -> String {
    let name = side.split_once(':').map_or(side, |(_, n)| n);
    let tail = |s: &str| s.get(1..).unwrap_or_default().to_string();
    let numbered = name.chars().nth(1).is_some_and(|c| c.is_ascii_digit());
    match name.chars().next() {
        _ if name.starts_with("face-") => "flat".into(),
        Some('f') if numbered => format!("face f{}", tail(name)),
        Some('e') if numbered => format!("edge e{}", tail(name)),
        Some('v') if numbered => format!("vertex v{}", tail(name)),
        _ => String::new(),
    }
}

/// The contacts of `tr` whose flag in `keep` is set, in time order.
pub(crate) fn contacts(scene: &Scene, tr: &Trajectory, keep: &[bool]) -> Vec<Contact> {
    tr.events
        .iter()
        .zip(keep)
        .filter(|(_, k)| **k)
        .map(|(e, _)| {
            let parts = match e.b {
                Party::Body(j) => scene.bodies.get(j).map(|b| b.geometry.parts.len()),
                Party::Obstacle(j) => scene.obstacles.get(j).map(|o| o.geometry.parts.len()),
            };
            let mut other = party_name(scene, e.b);
            if parts.unwrap_or(1) > 1 {
                other = format!("{other} part {}", e.feature.part_b);
            }
            let side_b = e.key.split_once('/').map_or("", |(_, b)| b);
            let feature = if e.key.contains(":patch/") {
                "flat".to_string()
            } else {
                feature_words(side_b)
            };
            let ending = if e.rest {
                "rests"
            } else if e.slide.is_some() {
                "slides"
            } else {
                ""
            };
            Contact {
                body: party_name(scene, Party::Body(e.a)),
                other,
                feature,
                ending: ending.into(),
            }
        })
        .collect()
}

/// How many phrases a description lists before "and N more".
const MOST_PHRASES: usize = 3;

/// What differs between the current contacts and an alternative's, e.g.
/// `egg1 now hits egg2; egg2 no longer hits ground` or `ball now hits hill
/// at face f2-3-9-10 instead of face f1-2-8-9`.
pub(crate) fn differences(current: &[Contact], alternative: &[Contact]) -> String {
    let mut counts: BTreeMap<&Contact, (usize, usize)> = BTreeMap::new();
    for c in current {
        counts.entry(c).or_default().0 += 1;
    }
    for c in alternative {
        counts.entry(c).or_default().1 += 1;
    }
    let mut new: Vec<&Contact> = Vec::new();
    let mut gone: Vec<&Contact> = Vec::new();
    let mut phrases: Vec<String> = Vec::new();
    for (c, &(now, then)) in &counts {
        match (now, then) {
            (0, _) => new.push(c),
            (_, 0) => gone.push(c),
            (a, b) if a != b => {
                phrases.push(format!("{} {} {b}× instead of {a}×", c.body, c.what()))
            }
            _ => {}
        }
    }
    // A contact that moved to another feature of the same party.
    let mut moved = Vec::new();
    new.retain(|n| {
        let k = gone
            .iter()
            .position(|g| g.body == n.body && g.other == n.other && g.ending == n.ending);
        match k {
            Some(k) => {
                let g = gone.remove(k);
                let was = if g.feature.is_empty() {
                    "elsewhere".to_string()
                } else {
                    g.feature.clone()
                };
                moved.push(format!("{} now {} instead of {was}", n.body, n.what()));
                false
            }
            None => true,
        }
    });
    let mut all: Vec<String> = moved;
    all.extend(new.iter().map(|c| format!("{} now {}", c.body, c.what())));
    all.extend(
        gone.iter()
            .map(|c| format!("{} no longer {}", c.body, c.what())),
    );
    all.extend(phrases);
    if all.is_empty() {
        return if current == alternative {
            "same collisions as now".into()
        } else {
            "same collisions in another order".into()
        };
    }
    let more = all.len().saturating_sub(MOST_PHRASES);
    all.truncate(MOST_PHRASES);
    let mut text = all.join("; ");
    if more > 0 {
        text.push_str(&format!("; and {more} more"));
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    fn c(body: &str, other: &str, feature: &str) -> Contact {
        Contact {
            body: body.into(),
            other: other.into(),
            feature: feature.into(),
            ending: String::new(),
        }
    }

    #[test]
    fn names_features_in_words() {
        assert_eq!(feature_words("0:f2-3-9-10"), "face f2-3-9-10");
        assert_eq!(feature_words("2:e3-4"), "edge e3-4");
        assert_eq!(feature_words("0:v12"), "vertex v12");
        assert_eq!(feature_words("0:plane"), "");
        assert_eq!(feature_words("0:ball"), "");
        assert_eq!(feature_words("1:face-b"), "flat");
    }

    #[test]
    fn says_what_is_new_gone_moved_or_repeated() {
        let hill = |f| c("ball", "hill", f);
        assert_eq!(
            differences(&[hill("face f1-2-8-9")], &[hill("face f2-3-9-10")]),
            "ball now hits hill at face f2-3-9-10 instead of face f1-2-8-9"
        );
        let eggs = c("egg1", "egg2", "");
        let ground = c("egg2", "ground", "");
        assert_eq!(
            differences(std::slice::from_ref(&ground), std::slice::from_ref(&eggs)),
            "egg1 now hits egg2; egg2 no longer hits ground"
        );
        assert_eq!(
            differences(
                std::slice::from_ref(&ground),
                &[ground.clone(), ground.clone()]
            ),
            "egg2 hits ground 2× instead of 1×"
        );
        assert_eq!(
            differences(
                &[ground.clone(), eggs.clone()],
                &[eggs.clone(), ground.clone()]
            ),
            "same collisions in another order"
        );
        assert_eq!(differences(&[], &[]), "same collisions as now");
        let many: Vec<Contact> = (0..5).map(|k| c("a", &format!("o{k}"), "")).collect();
        assert_eq!(
            differences(&[], &many),
            "a now hits o0; a now hits o1; a now hits o2; and 2 more"
        );
    }
}
