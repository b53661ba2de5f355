//! The folded stacks as a speedscope file (<https://www.speedscope.app>,
//! its "sampled" profile: each distinct stack one sample, weighted by
//! the cycles spent with exactly that stack).

use serde::{Deserialize, Serialize};

use crate::profile::Profile;

/// The file's schema, as speedscope names it.
pub const SCHEMA: &str = "https://www.speedscope.app/file-format-schema.json";

/// A speedscope file.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct File {
    /// [`SCHEMA`].
    #[serde(rename = "$schema")]
    pub schema: String,
    /// What the profiles share: the frames.
    pub shared: Shared,
    /// One profile: the tests' cycles.
    pub profiles: Vec<Sampled>,
    /// Shown as the file's title.
    pub name: String,
    /// The profile shown first.
    #[serde(rename = "activeProfileIndex")]
    pub active_profile_index: usize,
    /// What wrote it.
    pub exporter: String,
}

/// The frames, each a routine or label.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shared {
    /// Every frame, indexed by the samples.
    pub frames: Vec<Frame>,
}

/// A frame: a routine, a command, or the label cycles were spent at.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Frame {
    /// As the folded stacks name it.
    pub name: String,
}

/// A "sampled" profile: stacks and their weights.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Sampled {
    /// Always `sampled`.
    #[serde(rename = "type")]
    pub kind: String,
    /// Shown above the flame chart.
    pub name: String,
    /// `none`: the weights are the CPU's cycles.
    pub unit: String,
    /// 0.
    #[serde(rename = "startValue")]
    pub start_value: u64,
    /// Every cycle weighed.
    #[serde(rename = "endValue")]
    pub end_value: u64,
    /// Each stack, outermost frame first, as indices into the frames.
    pub samples: Vec<Vec<usize>>,
    /// The cycles of each stack.
    pub weights: Vec<u64>,
}

/// `profile`'s stacks as a speedscope file titled `title`.
#[must_use]
pub fn file(profile: &Profile, title: &str) -> File {
    let mut frames: Vec<Frame> = Vec::new();
    let mut ids: std::collections::HashMap<&str, usize> = std::collections::HashMap::new();
    let mut samples = Vec::new();
    let mut weights = Vec::new();
    for (stack, &cycles) in &profile.stacks {
        if cycles == 0 {
            continue;
        }
        let sample = stack
            .split(';')
            .map(|name| {
                *ids.entry(name).or_insert_with(|| {
                    frames.push(Frame {
                        name: name.to_owned(),
                    });
                    frames.len() - 1
                })
            })
            .collect();
        samples.push(sample);
        weights.push(cycles);
    }
    File {
        schema: SCHEMA.to_owned(),
        shared: Shared { frames },
        profiles: vec![Sampled {
            kind: "sampled".to_owned(),
            name: format!("{title} (cycles)"),
            unit: "none".to_owned(),
            start_value: 0,
            end_value: weights.iter().sum(),
            samples,
            weights,
        }],
        name: title.to_owned(),
        active_profile_index: 0,
        exporter: format!("scorpion-profile {}", env!("CARGO_PKG_VERSION")),
    }
}

/// [`file`] as JSON text.
///
/// # Errors
/// None in practice: every field is a string or a number.
pub fn json(profile: &Profile, title: &str) -> Result<String, serde_json::Error> {
    serde_json::to_string(&file(profile, title))
}
