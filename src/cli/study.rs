//! `bulge study`: one material across several specimens. Every specimen
//! goes through the whole pipeline (`bulge run`'s, written as `bulge run`
//! writes it under `DIR/specimens/<name>/`), in parallel; then
//! [`bulge::fit::study::gather`] gives the parameters' mean, scatter, the
//! 95 % interval of the mean, the pooled value and the outliers
//! (`study.csv`, `study.html`). A specimen whose inputs and settings did
//! not change since the last study into the same folder is read back, not
//! redone.

use std::fs;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::{Instant, UNIX_EPOCH};

use anyhow::anyhow;
use indicatif::{MultiProgress, ProgressBar};
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicUsize, Ordering};

use super::run::{Done, RunFlags, run_into, settings};
use super::{Failure, experiment_inputs, progress};
use bulge::experiment::{Experiment, Specimen};
use bulge::fit::inverse::{self, Measured, law_parameters};
use bulge::fit::study::{SpecimenFit, StudyInput, gather, joint};
use bulge::io::{InputError, OutputPlan};
use bulge::material::Material;
use bulge::pipeline::measured_heights;
use bulge::pipeline::{Observer, PipelineError, RunOptions, Settings, Stage, Timing};
use bulge::report::out_dir::OutDir;
use bulge::report::run_files::{OutFile, settings_table};
use bulge::report::study_files::{StudyInfo, study_files};

/// Flags of `bulge study`.
///
/// Example: `bulge study study.toml --out out/`, or
/// `bulge study s1/experiment.toml s2/experiment.toml s3/experiment.toml --out out/`.
#[derive(Debug, clap::Args)]
#[command(
    after_help = "A study file lists the specimens' experiment files (paths relative to the study file) and, \
optionally, settings shared by all in a [run] table (the keys of bulge run's [run] table; a flag overrides it, \
and it overrides each experiment's own [run]):

  [run]
  fit = \"mooney-rivlin\"

  [[specimens]]
  experiment = \"s1/experiment.toml\"
  name = \"s1\"      # optional; default: the experiment file's folder

Writes into --out: study.csv (one row per specimen, then mean, std, cv, ci95_low, ci95_high, pooled, joint), \
study.svg/png, study.html, and each specimen's run under specimens/<name>/ (the files of bulge run, with \
study_fit.toml: its corrected parameters, covariance and the fingerprint of its inputs). A specimen whose \
experiment file, input files (sizes and times, small ones by content) and settings did not change is read back \
from study_fit.toml instead of being redone. A failed specimen is left out when two others remain: the study is \
written and the exit status is 1. Exit status 2 when an input is refused."
)]
pub struct Args {
    /// A study file (TOML with [[specimens]] experiment = "..." and an
    /// optional [run] table), or two or more experiment files. Never
    /// written to.
    #[arg(required = true, num_args = 1.., value_name = "STUDY_OR_EXPERIMENTS")]
    pub inputs: Vec<PathBuf>,

    /// Output folder (created if missing; files of the same names are
    /// replaced). Required: bulge does not guess where to write.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,

    /// Redo every specimen, even those whose inputs and settings did not
    /// change since the last study into --out.
    #[arg(long)]
    pub redo: bool,

    /// The settings shared by every specimen (each also a key of the study
    /// file's [run] table).
    #[command(flatten)]
    pub flags: RunFlags,
}

/// The study file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct StudyFile {
    /// Settings shared by the specimens.
    #[serde(default)]
    run: Option<RunOptions>,
    /// The specimens.
    specimens: Vec<SpecimenEntry>,
}

/// One `[[specimens]]` entry.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct SpecimenEntry {
    /// The experiment file, relative to the study file.
    experiment: PathBuf,
    /// Its name (default: the experiment file's folder).
    #[serde(default)]
    name: Option<String>,
}

/// A specimen of the study, read.
struct Member {
    name: String,
    exp: Experiment,
    settings: Settings,
    fingerprint: String,
}

/// What `study_fit.toml` keeps of a specimen: what the study needs, and
/// the fingerprint of what it was made from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Record {
    /// Hash of the bulge version, the settings, the experiment file and the
    /// input files.
    pub fingerprint: String,
    /// The experiment file.
    pub experiment: String,
    /// The law fitted.
    pub law: String,
    /// The specimen's thickness used, m.
    pub thickness_m: f64,
    /// Parameter names with units.
    pub parameters: Vec<String>,
    /// Their corrected values.
    pub values: Vec<f64>,
    /// Their first-order standard errors.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub std_errors: Option<Vec<f64>>,
    /// Their covariance.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub covariance: Option<Vec<Vec<f64>>>,
    /// The specimen as the correction used it (for the joint fit).
    pub specimen: Specimen,
    /// The corrected law (without its provenance).
    pub material: Material,
    /// The heights the law was corrected to, when the window is circular
    /// and the law was corrected (for the joint fit).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub heights: Vec<Height>,
}

/// One measured height of a record.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Height {
    /// Pressure, Pa.
    pub pressure_pa: f64,
    /// Apex height, m.
    pub height_m: f64,
    /// Its standard deviation, m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height_std_m: Option<f64>,
}

/// The record's file name in the specimen's folder.
pub const RECORD: &str = "study_fit.toml";

/// What became of one specimen.
enum Outcome {
    Reused(Record),
    Done(Record, f64),
    Failed(Failure),
}

fn bad(m: String) -> Failure {
    Failure::BadInput(anyhow!(m))
}

/// 64-bit FNV-1a (a fixed, documented hash: the fingerprint must not
/// change between builds).
struct Fnv(u64);

impl Fnv {
    fn new() -> Self {
        Fnv(0xcbf2_9ce4_8422_2325)
    }
    fn bytes(&mut self, b: &[u8]) {
        for &x in b {
            self.0 ^= u64::from(x);
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
        // a separator, so that ("ab", "c") and ("a", "bc") differ
        self.0 ^= 0xff;
        self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
    }
}

/// Files up to this size are fingerprinted by content, larger ones by size
/// and modification time.
const BY_CONTENT: u64 = 1 << 20;

/// The fingerprint of a specimen: the bulge version, its settings, and each
/// input file (the experiment file, pressure log, template, video and
/// photos) by its name from the experiment's folder and its content, or
/// size and modification time when large.
fn fingerprint(exp: &Experiment, s: &Settings) -> String {
    let mut h = Fnv::new();
    h.bytes(env!("CARGO_PKG_VERSION").as_bytes());
    h.bytes(format!("{s:?}").as_bytes());
    for p in experiment_inputs(exp) {
        // named from the experiment's folder: the same study run from
        // another working folder is the same
        let name = p.strip_prefix(&exp.base_dir).unwrap_or(&p);
        h.bytes(name.to_string_lossy().as_bytes());
        match fs::metadata(&p) {
            Ok(m) if m.len() <= BY_CONTENT => match fs::read(&p) {
                Ok(b) => h.bytes(&b),
                Err(_) => h.bytes(b"unreadable"),
            },
            Ok(m) => {
                let t = m
                    .modified()
                    .ok()
                    .and_then(|t| t.duration_since(UNIX_EPOCH).ok())
                    .map_or(0, |d| d.as_nanos());
                h.bytes(format!("{} {t}", m.len()).as_bytes());
            }
            Err(_) => h.bytes(b"missing"),
        }
    }
    format!("{:016x}", h.0)
}

/// A specimen's name: the experiment file's folder, else its file stem.
fn default_name(path: &Path) -> String {
    let folder = path
        .parent()
        .and_then(|p| p.file_name())
        .map(|n| n.to_string_lossy().into_owned());
    folder
        .filter(|n| !n.is_empty() && n != "." && n != "..")
        .unwrap_or_else(|| {
            path.file_stem()
                .map_or(String::new(), |s| s.to_string_lossy().into_owned())
        })
}

fn valid_name(n: &str) -> bool {
    !n.is_empty()
        && n != "."
        && n != ".."
        && n.chars()
            .all(|c| c.is_ascii_alphanumeric() || "._-".contains(c))
}

/// Whether a TOML file is a study file (it has `specimens`).
fn is_study_file(path: &Path) -> Result<bool, Failure> {
    let text = fs::read_to_string(path).map_err(|e| {
        Failure::BadInput(InputError::file(path, format!("cannot read the file: {e}")).into())
    })?;
    Ok(text
        .parse::<toml::Table>()
        .map(|t| t.contains_key("specimens"))
        .unwrap_or(false))
}

/// The study as read: its title, the specimens (name, experiment) and the
/// shared options.
type Read = (String, Vec<(String, Experiment)>, RunOptions);

/// The study from the command line's inputs.
fn members_of(args: &Args) -> Result<Read, Failure> {
    let study = match args.inputs.as_slice() {
        [one] if is_study_file(one)? => Some(one.clone()),
        [one] => {
            return Err(bad(format!(
                "{}: a study needs two specimens or more: give a study file with [[specimens]] entries, or two or more experiment files",
                one.display()
            )));
        }
        many => {
            for p in many {
                if is_study_file(p)? {
                    return Err(bad(format!(
                        "{} is a study file: give either one study file or experiment files, not both",
                        p.display()
                    )));
                }
            }
            None
        }
    };
    let mut members = Vec::new();
    let (title, shared) = match &study {
        Some(path) => {
            let f: StudyFile = bulge::io::read_toml(path)?;
            if f.specimens.len() < 2 {
                return Err(bad(format!(
                    "{}: [[specimens]] lists {}: a study needs two specimens or more (add `[[specimens]]` entries with `experiment = \"...\"`)",
                    path.display(),
                    f.specimens.len()
                )));
            }
            let base = path.parent().unwrap_or(Path::new(""));
            for (k, e) in f.specimens.iter().enumerate() {
                let file = base.join(&e.experiment);
                let exp = Experiment::read(&file).map_err(|err| {
                    bad(format!(
                        "{}: [[specimens]] entry {} (experiment = \"{}\", relative to the study file): {err}",
                        path.display(),
                        k + 1,
                        e.experiment.display()
                    ))
                })?;
                let name = match &e.name {
                    Some(n) if !valid_name(n) => {
                        return Err(bad(format!(
                            "{}: [[specimens]] entry {}: name = \"{n}\" cannot name a folder: use letters, digits, '.', '_' and '-'",
                            path.display(),
                            k + 1
                        )));
                    }
                    Some(n) => n.clone(),
                    None => default_name(&file),
                };
                members.push((name, exp));
            }
            (path.display().to_string(), f.run.unwrap_or_default())
        }
        None => {
            for p in &args.inputs {
                members.push((default_name(p), Experiment::read(p)?));
            }
            (
                format!("{} experiment files", args.inputs.len()),
                RunOptions::default(),
            )
        }
    };
    for (i, (n, e)) in members.iter().enumerate() {
        if !valid_name(n) {
            return Err(bad(format!(
                "{}: the specimen's name `{n}` (its folder's) cannot name an output folder: give it a `name` in a study file (letters, digits, '.', '_' and '-')",
                e.path.display()
            )));
        }
        // One experiment listed twice would count one specimen twice in the
        // mean, its interval and the pooled fit.
        let same = |a: &Path, b: &Path| match (a.canonicalize(), b.canonicalize()) {
            (Ok(a), Ok(b)) => a == b,
            _ => a == b,
        };
        if let Some((m, first)) = members[..i].iter().find(|(_, f)| same(&f.path, &e.path)) {
            return Err(bad(format!(
                "the specimens `{m}` and `{n}` are one experiment file ({}): each specimen is counted once in the mean, its interval and the pooled fit; list it once",
                first.path.display()
            )));
        }
        if let Some((_, first)) = members[..i].iter().find(|(m, _)| m == n) {
            return Err(bad(format!(
                "two specimens are named `{n}` ({} and {}): give each a distinct `name` in the study file (or keep each experiment in a folder of its own name)",
                first.path.display(),
                e.path.display()
            )));
        }
    }
    Ok((title, members, shared))
}

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

/// The record of a finished run.
fn record(m: &Member, o: &bulge::pipeline::RunOutput) -> Result<Record, PipelineError> {
    let (parameters, values, _) = law_parameters(&o.fit.material.model).ok_or_else(|| {
        PipelineError::Input(format!(
            "the fitted law ({}) has no parameters to compare across specimens",
            o.fit.material.model.name()
        ))
    })?;
    let u = o.fit.refined.as_ref().and_then(|r| r.uncertainty.as_ref());
    Ok(Record {
        fingerprint: m.fingerprint.clone(),
        experiment: m.exp.path.display().to_string(),
        law: m.settings.fit.label(),
        thickness_m: o.specimen.thickness_m,
        parameters,
        values,
        std_errors: u.map(|u| u.std_errors()),
        covariance: u.map(|u| {
            let c = u.covariance();
            (0..c.nrows())
                .map(|i| (0..c.ncols()).map(|j| c[(i, j)]).collect())
                .collect()
        }),
        specimen: o.specimen,
        material: Material {
            fit: None,
            ..o.fit.material.clone()
        },
        heights: if m.settings.window.is_circle() && o.fit.refined.is_some() {
            measured_heights(&o.stress.points)
                .iter()
                .map(|q| Height {
                    pressure_pa: q.pressure_pa,
                    height_m: q.height_m,
                    height_std_m: q.height_std_m,
                })
                .collect()
        } else {
            vec![]
        },
    })
}

/// The earlier record of a specimen, when it was made from the same inputs
/// and settings.
fn reusable(dir: &Path, m: &Member) -> Option<Record> {
    let text = fs::read_to_string(dir.join(RECORD)).ok()?;
    let r: Record = toml::from_str(&text).ok()?;
    (r.fingerprint == m.fingerprint).then_some(r)
}

/// One specimen: read back, or run into its folder.
fn one(m: &Member, out: &Path, redo: bool, bars: &MultiProgress) -> Outcome {
    let dir = out.join("specimens").join(&m.name);
    if !redo && let Some(r) = reusable(&dir, m) {
        return Outcome::Reused(r);
    }
    let lock = match OutDir::lock(&dir) {
        Ok(d) => d,
        Err(e) if e.is_bad_input() => return Outcome::Failed(bad(e.to_string())),
        Err(e) => return Outcome::Failed(Failure::Failed(e.into())),
    };
    let obs = Bar {
        name: m.name.clone(),
        bar: bars.add(progress(1, &m.name)),
    };
    let t = Instant::now();
    let rec: Mutex<Option<Record>> = Mutex::new(None);
    let result = run_into(&m.exp, &m.settings, &lock, &obs, |o| {
        let r = record(m, o)?;
        let text = bulge::io::to_toml_string(&r)
            .map_err(|e| PipelineError::Output(format!("{RECORD}: {e}")))?;
        *rec.lock().expect("record") = Some(r);
        Ok(vec![OutFile {
            name: RECORD,
            stage: Stage::Report,
            bytes: text.into_bytes(),
        }])
    });
    obs.bar.finish_and_clear();
    match result {
        Ok(Done { .. }) => match rec.into_inner().expect("record") {
            Some(r) => Outcome::Done(r, t.elapsed().as_secs_f64()),
            None => Outcome::Failed(Failure::Failed(anyhow!("no record written"))),
        },
        Err(f) => Outcome::Failed(f),
    }
}

/// `f` on every member, on as many threads of their own as rayon has
/// workers, each taking the next member when done; the results in the
/// members' order. Not on rayon's workers: the tracker waits on its own
/// rayon jobs (the photos it decodes), which a pool whose every worker
/// waits so would never run.
fn in_parallel<T: Send>(members: &[Member], f: impl Fn(&Member) -> T + Sync) -> Vec<T> {
    let next = AtomicUsize::new(0);
    let slots: Vec<Mutex<Option<T>>> = members.iter().map(|_| Mutex::new(None)).collect();
    let threads = rayon::current_num_threads().clamp(1, members.len().max(1));
    std::thread::scope(|scope| {
        for _ in 0..threads {
            scope.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    let Some(m) = members.get(i) else { break };
                    *slots[i].lock().expect("result slot") = Some(f(m));
                }
            });
        }
    });
    slots
        .into_iter()
        .map(|s| {
            s.into_inner()
                .expect("result slot")
                .expect("every member done")
        })
        .collect()
}

/// Runs `bulge study`.
pub fn run(args: Args) -> Result<(), Failure> {
    super::output_folder(&args.out, "--out")?;
    let (title, read, shared) = members_of(&args)?;
    let flags = args.flags.options().or(shared);
    let mut members = Vec::new();
    for (name, exp) in read {
        let mut s = settings(flags.clone(), &exp)?;
        // A study fits one law to every specimen: `auto` would let each
        // specimen's heights choose their own, so a study keeps the
        // paper's polynomial E(eps) unless a law is named.
        if s.fit == bulge::fit::FitModel::Auto {
            let degree = flags
                .degree
                .or_else(|| {
                    bulge::pipeline::RunOptions::from_experiment(&exp)
                        .ok()?
                        .degree
                })
                .unwrap_or(4);
            s.fit = bulge::fit::FitModel::Quartic { degree };
        }
        let fingerprint = fingerprint(&exp, &s);
        members.push(Member {
            name,
            exp,
            settings: s,
            fingerprint,
        });
    }
    let first = &members[0];
    if let Some(m) = members
        .iter()
        .find(|m| m.settings.fit != first.settings.fit)
    {
        return Err(bad(format!(
            "{}: specimen {} fits {} but {} fits {}: a study fits one law to every specimen; set `fit` in the study file's [run] table or give --fit",
            m.exp.path.display(),
            m.name,
            m.settings.fit.label(),
            first.name,
            first.settings.fit.label()
        )));
    }
    let mut plan = OutputPlan::new().inputs(&args.inputs);
    for m in &members {
        plan = plan.inputs(experiment_inputs(&m.exp));
    }
    super::guard(plan.output_as("--out", &args.out))?;
    let out = args.out.as_path();
    let top = OutDir::lock(out).map_err(|e| match e.is_bad_input() {
        true => Failure::BadInput(anyhow!("--out: {e}")),
        false => Failure::Failed(e.into()),
    })?;
    if let Some(h) = top.taken_over() {
        eprintln!(
            "note: {} held the lock file of a study that ended without removing it ({h}); taken over, and the study resumed",
            out.display()
        );
    }
    eprintln!(
        "{} specimens, {} law corrected to each one's heights, into {}",
        members.len(),
        first.settings.fit.label(),
        out.join("specimens").display()
    );
    let bars = MultiProgress::new();
    let outcomes = in_parallel(&members, |m| one(m, out, args.redo, &bars));
    let _ = bars.clear();

    let mut fits = Vec::new();
    let mut names: Vec<String> = Vec::new();
    let mut info = StudyInfo {
        title,
        law: first.settings.fit.label(),
        ..StudyInfo::default()
    };
    let mut failures = Vec::new();
    let mut joint_inputs: Vec<(StudyInput, Material)> = Vec::new();
    for (m, o) in members.iter().zip(outcomes) {
        let r = match o {
            Outcome::Reused(r) => {
                eprintln!(
                    "  reused  {}: inputs and settings unchanged, read back from {}",
                    m.name,
                    out.join("specimens").join(&m.name).join(RECORD).display()
                );
                info.reused.push(m.name.clone());
                r
            }
            Outcome::Done(r, secs) => {
                eprintln!("  done    {} in {secs:.1} s", m.name);
                r
            }
            Outcome::Failed(f) => {
                eprintln!("  failed  {}: {:#}", m.name, f.error());
                info.failed
                    .push((m.name.clone(), format!("{:#}", f.error())));
                failures.push(f);
                continue;
            }
        };
        if names.is_empty() {
            names = r.parameters.clone();
        }
        if !r.heights.is_empty() {
            joint_inputs.push((
                StudyInput {
                    name: m.name.clone(),
                    specimen: r.specimen,
                    measured: r
                        .heights
                        .iter()
                        .map(|h| Measured {
                            pressure_pa: h.pressure_pa,
                            height_m: h.height_m,
                            height_std_m: h.height_std_m,
                        })
                        .collect(),
                    options: inverse::Options::default(),
                },
                r.material.clone(),
            ));
        }
        info.thickness_m.push(r.thickness_m);
        fits.push(SpecimenFit {
            name: m.name.clone(),
            values: r.values,
            std_errors: r.std_errors,
            outlier: vec![],
        });
    }
    if !info.reused.is_empty() {
        eprintln!(
            "reused {} of {} specimens ({}); --redo redoes them",
            info.reused.len(),
            members.len(),
            info.reused.join(", ")
        );
    }
    if fits.len() < 2 {
        let msg = anyhow!(
            "the study needs two specimens or more and only {} of {} finished (see the failures above); nothing written to {} besides the specimens' folders",
            fits.len(),
            members.len(),
            out.display()
        );
        return Err(
            if failures.iter().all(|f| matches!(f, Failure::BadInput(_))) {
                Failure::BadInput(msg)
            } else {
                Failure::Failed(msg)
            },
        );
    }
    if !failures.is_empty() {
        eprintln!(
            "going on with the {} specimens that finished; {} left out: {}",
            fits.len(),
            info.failed.len(),
            info.failed
                .iter()
                .map(|(n, _)| n.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    let study = gather(names, fits).map_err(|e| bad(format!("{e}")))?;
    // one law fitted to every specimen's heights together, from the first
    // specimen's corrected law
    if joint_inputs.len() == study.specimens.len() {
        let start = joint_inputs[0].1.clone();
        let inputs: Vec<StudyInput> = joint_inputs.into_iter().map(|(i, _)| i).collect();
        match joint(&inputs, &start) {
            Ok(j) if j.names == study.names => info.joint = Some((j.values, j.std_errors)),
            Ok(_) => {}
            Err(e) => eprintln!("no joint fit of the specimens' heights: {e}"),
        }
    }
    info.settings = settings_table(&first.settings, &first.exp, &[])
        .into_iter()
        .filter(|(k, _)| k != "experiment" && !k.starts_with("pressures"))
        .collect();
    info.settings.push((
        "specimens".into(),
        members
            .iter()
            .map(|m| format!("{}: {}", m.name, m.exp.path.display()))
            .collect::<Vec<_>>()
            .join("; "),
    ));
    let files = study_files(&study, &info).map_err(|e| Failure::Failed(e.into()))?;
    let status = if failures.is_empty() {
        "complete".to_string()
    } else {
        format!(
            "partial: {} of {} specimens",
            study.specimens.len(),
            members.len()
        )
    };
    top.write_set(&files.files, &status)
        .map_err(|e| Failure::Failed(e.into()))?;
    print!("\n{}", files.terminal);
    println!("\nwrote {}", out.join("study.html").display());
    if !failures.is_empty() {
        return Err(Failure::Failed(anyhow!(
            "the study is partial: {} left out ({}; see above); the study of the {} others is in {}",
            info.failed.len(),
            info.failed
                .iter()
                .map(|(n, _)| n.as_str())
                .collect::<Vec<_>>()
                .join(", "),
            study.specimens.len(),
            out.display()
        )));
    }
    Ok(())
}
