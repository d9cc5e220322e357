//! One specimen of a study ([`bulge::study::command::one`]: read back from
//! its record when its inputs and settings are unchanged, or run into its
//! own folder) with a progress bar.

use std::path::Path;

use indicatif::{MultiProgress, ProgressBar};

use super::super::progress;
use bulge::pipeline::{Observer, Stage, Timing};
use bulge::study::Member;
use bulge::study::command::Outcome;

/// One bar per specimen: its name, the current stage and its steps.
struct Bar {
    name: String,
    bar: ProgressBar,
}

impl Observer for Bar {
    fn start(&self, stage: Stage, steps: u64) {
        self.bar.set_length(steps.max(1));
        self.bar.set_position(0);
        self.bar
            .set_message(format!("{} {}", self.name, stage.name()));
    }
    fn tick(&self) {
        self.bar.inc(1);
    }
    fn done(&self, t: &Timing) {
        self.bar.set_position(self.bar.length().unwrap_or(1));
        self.bar
            .set_message(format!("{} {} done", self.name, t.stage.name()));
    }
}

/// One specimen: read back, or run into its folder with a bar.
pub(super) fn one(m: &Member, out: &Path, redo: bool, bars: &MultiProgress) -> Outcome {
    let obs = Bar {
        name: m.name.clone(),
        bar: bars.add(progress(1, &m.name)),
    };
    let o = bulge::study::command::one(m, out, redo, &obs);
    obs.bar.finish_and_clear();
    o
}
