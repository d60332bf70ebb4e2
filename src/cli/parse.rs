//! The command line's value parsers: each parameter is checked by the one
//! function its other sources (sessions, the editor's controls) use.

use super::ViewArg;

/// `--resolution`, checked by its spec: the one check sessions and the editor use.
pub(super) fn parse_resolution(text: &str) -> Result<u32, String> {
    parse_parameter(crate::coords::Parameter::Resolution, text)
}

/// `--grid`, checked by its spec.
pub(super) fn parse_grid(text: &str) -> Result<u32, String> {
    parse_parameter(crate::coords::Parameter::Grid, text)
}

/// `--poisson-ratio`: a decimal, held in thousandths, checked by its spec.
pub(super) fn parse_poisson_ratio(text: &str) -> Result<u32, String> {
    parse_parameter(crate::coords::Parameter::PoissonRatio, text)
}

/// `--bulging`: a decimal, held in hundredths, checked by its spec.
pub(super) fn parse_bulging(text: &str) -> Result<u32, String> {
    parse_parameter(crate::coords::Parameter::Bulging, text)
}

/// `--local-blend`: a decimal, held in hundredths, checked by its spec.
pub(super) fn parse_local_blend(text: &str) -> Result<u32, String> {
    parse_parameter(crate::coords::Parameter::LocalBlend, text)
}

fn parse_parameter(parameter: crate::coords::Parameter, text: &str) -> Result<u32, String> {
    parameter.spec().parse(text)
}

/// `--difference-limit`: a percentage of the cage diagonal, with or without the
/// % sign, in the range the toolbar offers and sessions are held to
/// ([`crate::app::compare::DIFFERENCE_LIMITS`]).
pub(super) fn parse_percent(text: &str) -> Result<f32, String> {
    let number = text.trim().trim_end_matches('%');
    let percent: f32 = number
        .parse()
        .map_err(|_| format!("'{text}' is not a percentage (e.g. 0.5 or 0.5%)"))?;
    crate::app::compare::check_difference_limit(percent / 100.0).map(|_| percent)
}

/// `--mesh-object`, `--cage-object`: checked as Python's `object=` is.
pub(super) fn parse_object_name(text: &str) -> Result<String, String> {
    crate::formats::check_object_name(text).map(str::to_owned)
}

/// `--animate`: a duration in seconds, finite and above 0.
pub(super) fn parse_seconds(text: &str) -> Result<f32, String> {
    match text.trim().parse::<f32>() {
        Ok(seconds) if seconds.is_finite() && seconds > 0.0 => Ok(seconds),
        _ => Err(format!("'{text}' is not a duration in seconds above 0")),
    }
}

pub(super) fn parse_view(value: &str) -> Result<ViewArg, String> {
    match value {
        "side-by-side" => Ok(ViewArg::SideBySide),
        "difference" => Ok(ViewArg::Difference),
        other => crate::coords::Method::from_id(other)
            .map(ViewArg::Single)
            .ok_or_else(|| {
                let methods: Vec<&str> =
                    crate::coords::Method::ALL.iter().map(|m| m.id()).collect();
                format!(
                    "expected side-by-side, difference or a method ({})",
                    methods.join(", ")
                )
            }),
    }
}

/// `--triangulate`'s values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum TriangulateArg {
    /// Along each quad's shorter diagonal.
    Shorter,
    /// Along each quad's longer diagonal.
    Longer,
}

impl TriangulateArg {
    pub(super) fn split(self) -> crate::coords::QuadSplit {
        match self {
            TriangulateArg::Shorter => crate::coords::QuadSplit::Shorter,
            TriangulateArg::Longer => crate::coords::QuadSplit::Longer,
        }
    }
}
