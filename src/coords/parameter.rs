//! A family's one parameter as data: its range, its reading from text and its
//! check, the same for the command line, Python, saved files and the editor.

use super::family::{DEFAULT_RESOLUTION, EXACT_RESOLUTION};

/// A family's one parameter (a resolution, a grid size, a Poisson ratio), held
/// as a whole number of `1/scale` units.
#[derive(Clone, Copy, Debug)]
pub struct ParameterSpec {
    /// Which field of [`super::BindOptions`] holds it.
    pub key: Parameter,
    /// Shown beside its control, e.g. "PMVC resolution".
    pub label: &'static str,
    /// The command-line flag, e.g. "--resolution".
    pub flag: &'static str,
    /// The values the editor offers.
    pub choices: &'static [u32],
    pub default: u32,
    /// The smallest and largest values accepted from any source ([`Self::validate`]).
    pub min: u32,
    pub max: u32,
    /// Values outside `min..=max` that mean something else, by name
    /// (PMVC's "exact": no cube map).
    pub named: &'static [NamedValue],
    /// How a value reads in titles, e.g. "32²" or "exact".
    pub format: fn(u32) -> String,
    /// Units per one: 1 for whole numbers, 1000 for a value in thousandths
    /// (read and written as a decimal, "0.3").
    pub scale: u32,
    /// The held value that means zero: the units below it are negative values
    /// (an auxetic Poisson ratio); 0 for a parameter that cannot be negative.
    pub zero: u32,
}

/// A parameter value with a name, written and read as that name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NamedValue {
    pub value: u32,
    pub name: &'static str,
}

/// A parameter value outside its family's range.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "{id} {} is out of range: the {label} must be {} to {}{}",
    signed_decimal(*.value, *.zero, *.scale),
    signed_decimal(u64::from(*.min), *.zero, *.scale),
    signed_decimal(u64::from(*.max), *.zero, *.scale),
    or_named(named)
)]
pub struct ParameterError {
    /// The name saved files give it ("resolution").
    pub id: &'static str,
    pub label: &'static str,
    pub value: u64,
    pub min: u32,
    pub max: u32,
    pub named: &'static [NamedValue],
    pub scale: u32,
    pub zero: u32,
}

/// `value` units of `1/scale` above `zero` as a signed decimal: "-0.3" for 700
/// thousandths above a zero of 1000.
pub fn signed_decimal(value: u64, zero: u32, scale: u32) -> String {
    match value.checked_sub(u64::from(zero)) {
        Some(above) => decimal(above, scale),
        None => format!("-{}", decimal(u64::from(zero) - value, scale)),
    }
}

/// `value` units of `1/scale` as a decimal: "0.3" for 300 thousandths.
pub fn decimal(value: u64, scale: u32) -> String {
    if scale <= 1 {
        return value.to_string();
    }
    let digits = scale.ilog10() as usize;
    let text = format!(
        "{}.{:0digits$}",
        value / u64::from(scale),
        value % u64::from(scale)
    );
    text.trim_end_matches('0').trim_end_matches('.').to_owned()
}

/// `, or "exact"` after a range, for a parameter with named values.
fn or_named(named: &[NamedValue]) -> String {
    named
        .iter()
        .map(|named| format!(", or \"{}\"", named.name))
        .collect()
}

impl ParameterSpec {
    /// The one check of a value, wherever it comes from (the command line, a
    /// session, the editor's controls): `value` when it is in `min..=max` or
    /// one of the named values.
    pub fn validate(&self, value: u64) -> Result<u32, ParameterError> {
        match u32::try_from(value) {
            Ok(value) if (self.min..=self.max).contains(&value) => Ok(value),
            Ok(value) if self.named.iter().any(|named| named.value == value) => Ok(value),
            _ => Err(self.out_of_range(value)),
        }
    }

    fn out_of_range(&self, value: u64) -> ParameterError {
        ParameterError {
            id: self.key.id(),
            label: self.label,
            value,
            min: self.min,
            max: self.max,
            named: self.named,
            scale: self.scale,
            zero: self.zero,
        }
    }

    /// The number a held value stands for: `(value − zero) / scale`.
    pub fn number(&self, value: u32) -> f64 {
        (f64::from(value) - f64::from(self.zero)) / f64::from(self.scale)
    }

    /// A held value as text: the decimal it stands for ("0.3", "-0.2", "32").
    pub fn text(&self, value: u32) -> String {
        signed_decimal(value.into(), self.zero, self.scale)
    }

    /// The one reading of a value from text (the command line, Python, saved
    /// files): a whole number checked by [`Self::validate`], or a value's name.
    pub fn parse(&self, text: &str) -> Result<u32, String> {
        let text = text.trim();
        if let Some(named) = self
            .named
            .iter()
            .find(|n| n.name.eq_ignore_ascii_case(text))
        {
            return Ok(named.value);
        }
        if self.scale > 1 {
            return self.parse_decimal(text);
        }
        let value: u64 = text.parse().map_err(|_| {
            format!(
                "'{text}' is not a whole number{}",
                or_named(self.named).replacen(',', "", 1)
            )
        })?;
        self.validate_number(value)
            .map_err(|error| error.to_string())
    }

    /// A decimal (`scale` > 1) in units of `1/scale`: "0.3" is 300 thousandths.
    fn parse_decimal(&self, text: &str) -> Result<u32, String> {
        let number: f64 = match text.parse() {
            Ok(number) if f64::is_finite(number) => number,
            _ => return Err(format!("'{text}' is not a number")),
        };
        self.validate_decimal(number)
            .map_err(|error| error.to_string())
    }

    /// A decimal value checked as [`Self::validate_number`], held as
    /// `zero` plus the number in `1/scale` units, rounded to the nearest.
    pub fn validate_decimal(&self, number: f64) -> Result<u32, String> {
        let units = (number * f64::from(self.scale)).round() + f64::from(self.zero);
        if !(units >= 0.0 && units <= f64::from(u32::MAX)) {
            return Err(format!(
                "{} {number} is out of range: the {} must be {} to {}",
                self.key.id(),
                self.label,
                self.text(self.min),
                self.text(self.max)
            ));
        }
        self.validate_number(units as u64)
            .map_err(|error| error.to_string())
    }

    /// [`Self::validate`] of a value given as a number by a user: a named
    /// value is given by its name, so its code (PMVC's exact is 0) is refused.
    pub fn validate_number(&self, value: u64) -> Result<u32, ParameterError> {
        match u32::try_from(value) {
            Ok(value) if (self.min..=self.max).contains(&value) => Ok(value),
            _ => Err(self.out_of_range(value)),
        }
    }

    /// The name of `value`, if it is a named one.
    pub fn name_of(&self, value: u32) -> Option<&'static str> {
        self.named
            .iter()
            .find(|named| named.value == value)
            .map(|named| named.name)
    }
}

/// The parameters families can have; each is a field of [`super::BindOptions`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Parameter {
    /// Cube-map texels along one face edge (PMVC).
    Resolution,
    /// Grid cells along the cage's longest side (harmonic coordinates, BBW).
    Grid,
    /// The material's Poisson ratio, in thousandths above a zero of 1000
    /// (Somigliana coordinates).
    PoissonRatio,
    /// The bulging γ of a deformation, in hundredths (Somigliana coordinates):
    /// read when the weights deform a pose, not when they are bound.
    Bulging,
    /// The local/global blend of a deformation, in hundredths (Somigliana
    /// coordinates): read when the weights deform a pose.
    LocalBlend,
}

impl Parameter {
    pub const ALL: [Parameter; 5] = [
        Parameter::Resolution,
        Parameter::Grid,
        Parameter::PoissonRatio,
        Parameter::Bulging,
        Parameter::LocalBlend,
    ];

    /// The name saved files give it.
    pub fn id(self) -> &'static str {
        match self {
            Parameter::Resolution => "resolution",
            Parameter::Grid => "grid",
            Parameter::PoissonRatio => "poisson_ratio",
            Parameter::Bulging => "bulging",
            Parameter::LocalBlend => "local_blend",
        }
    }

    /// Its spec: label, flag, range and the editor's choices.
    pub fn spec(self) -> &'static ParameterSpec {
        match self {
            Parameter::Resolution => &RESOLUTION,
            Parameter::Grid => &GRID,
            Parameter::PoissonRatio => &super::somigliana::POISSON_RATIO_SETTING,
            Parameter::Bulging => &super::somigliana::BULGING_SETTING,
            Parameter::LocalBlend => &super::somigliana::LOCAL_BLEND_SETTING,
        }
    }

    /// Whether a family reads it when its weights deform a pose rather than
    /// when they are bound ([`super::FamilySpec::deform_parameters`]).
    pub fn read_when_deforming(self) -> bool {
        super::Method::ALL
            .iter()
            .any(|method| (method.spec().deform_parameters.iter()).any(|spec| spec.key == self))
    }

    /// [`ParameterSpec::validate`] of this parameter.
    pub fn validate(self, value: u64) -> Result<u32, ParameterError> {
        self.spec().validate(value)
    }
}

/// PMVC's cube-map resolution. Past 1024 the six faces of one point's cube map
/// alone are 24 MiB and a bind of a real mesh takes hours.
pub(super) const RESOLUTION: ParameterSpec = ParameterSpec {
    key: Parameter::Resolution,
    label: "PMVC resolution",
    flag: "--resolution",
    choices: &[16, 32, 64, 128, EXACT_RESOLUTION],
    default: DEFAULT_RESOLUTION,
    min: 1,
    max: 1024,
    named: &[NamedValue {
        value: EXACT_RESOLUTION,
        name: "exact",
    }],
    format: |value| match value {
        EXACT_RESOLUTION => "exact".to_owned(),
        side => format!("{side}²"),
    },
    scale: 1,
    zero: 0,
};

/// Harmonic coordinates' grid: fewer than `MIN_GRID` cells cannot resolve a
/// cage; 2048 cells along the longest side is already billions of nodes.
pub(super) const GRID: ParameterSpec = ParameterSpec {
    key: Parameter::Grid,
    label: "harmonic grid",
    flag: "--grid",
    choices: &[32, 64, 128],
    default: super::harmonic::DEFAULT_GRID,
    min: super::harmonic::MIN_GRID,
    max: 2048,
    named: &[],
    format: |value| format!("grid {value}"),
    scale: 1,
    zero: 0,
};

/// Bounded biharmonic weights' grid: the `--grid` of harmonic coordinates, with
/// a smaller default, since the factor of the biharmonic system grows about as
/// the grid's fourth power (a cube cage at grid 32 factorises into 45 million
/// entries, 360 MB).
pub(super) const BBW_GRID: ParameterSpec = ParameterSpec {
    label: "BBW grid",
    choices: &[16, 32, 48],
    default: super::bbw::DEFAULT_GRID,
    ..GRID
};

/// Local barycentric coordinates' grid: the `--grid` of harmonic coordinates,
/// with a smaller default, since every cage vertex's weights are solved
/// together (memory grows with the grid's cube times the cage's vertices).
pub(super) const LBC_GRID: ParameterSpec = ParameterSpec {
    label: "LBC grid",
    choices: &[16, 32, 48],
    default: super::lbc::DEFAULT_GRID,
    ..GRID
};
