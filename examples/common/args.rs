//! Command-line options shared by the sweep examples: `--name value`
//! pairs read from the arguments as given.

// Each example uses the helpers it needs.
#![allow(dead_code)]

use bulge::track::synth::sweep;

type Result<T> = std::result::Result<T, Box<dyn std::error::Error>>;

/// The number after `name`, or `default`.
pub fn number(args: &[String], name: &str, default: u64) -> Result<u64> {
    Ok(match args.iter().position(|a| a == name) {
        Some(i) => args
            .get(i + 1)
            .ok_or(format!("{name} needs a number"))?
            .parse()?,
        None => default,
    })
}

/// The comma-separated list after `name`, or `default`.
pub fn list<T>(args: &[String], name: &str, default: &[T]) -> Result<Vec<T>>
where
    T: std::str::FromStr + Clone,
    T::Err: std::error::Error + 'static,
{
    Ok(match args.iter().position(|a| a == name) {
        Some(i) => args
            .get(i + 1)
            .ok_or(format!("{name} needs a comma-separated list"))?
            .split(',')
            .map(str::parse)
            .collect::<std::result::Result<_, _>>()?,
        None => default.to_vec(),
    })
}

/// The photo sizes of `--sizes` (by default 640x480 to 1280x960).
pub fn sizes(args: &[String]) -> Result<Vec<(usize, usize)>> {
    Ok(match args.iter().position(|a| a == "--sizes") {
        Some(i) => sweep::parse_sizes(
            args.get(i + 1)
                .ok_or("--sizes needs a list such as 640x480,800x600")?,
        )
        .map_err(|e| format!("--sizes: {e}"))?,
        None => sweep::SIZES.to_vec(),
    })
}
