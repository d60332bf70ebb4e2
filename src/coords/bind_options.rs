//! What a bind is asked for: the family, its parameters and what to do with
//! the cage's quads, with the one check of the parameters; and the settings the
//! family reads when its weights deform a pose (Somigliana's bulging), which
//! are not part of the weights.

use super::{
    harmonic, ColumnMoves, Method, Parameter, ParameterError, ParameterSpec, QuadSplit,
    QuadSupport, DEFAULT_RESOLUTION, EXACT_RESOLUTION,
};
use crate::geometry::{Cage, PointClasses};
use glam::DVec3;

/// What to bind.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BindOptions {
    pub method: Method,
    /// Cube-map resolution for PMVC; ignored by the others.
    pub resolution: u32,
    /// Grid cells along the cage's longest side for harmonic coordinates; ignored
    /// by the others.
    pub grid: u32,
    /// Somigliana coordinates' Poisson ratio as held by its setting (thousandths
    /// above 1000: [`Self::poisson_ratio`] gives ν);
    /// ignored by the others.
    pub poisson_ratio: u32,
    /// Somigliana coordinates' bulging γ, in hundredths ([`Self::bulging`] gives
    /// γ): read when the weights deform a pose, so it is not part of the
    /// weights ([`Self::same_weights_as`] ignores it); ignored by the others.
    pub bulging: u32,
    /// Somigliana coordinates' local/global blend, in hundredths
    /// ([`Self::local_blend`] gives it): read when deforming, as bulging is.
    pub local_blend: u32,
    /// Whether the cage's quads stay bilinear patches (`None`, the default) or are
    /// split into triangles along a diagonal first (`--triangulate`). Families that
    /// only take triangles (Green) split along the shorter one when this is `None`.
    pub quads: QuadSplit,
}

impl BindOptions {
    /// The options for `method` with every parameter at its default (the
    /// family's own default for its parameter, e.g. BBW's grid).
    pub fn for_method(method: Method) -> Self {
        let mut options = Self {
            method,
            ..Self::default()
        };
        if let Some(spec) = method.spec().parameter {
            options.set(spec.key, spec.default);
        }
        options
    }

    /// The value of `parameter` in these options.
    pub fn get(&self, parameter: Parameter) -> u32 {
        match parameter {
            Parameter::Resolution => self.resolution,
            Parameter::Grid => self.grid,
            Parameter::PoissonRatio => self.poisson_ratio,
            Parameter::Bulging => self.bulging,
            Parameter::LocalBlend => self.local_blend,
        }
    }

    pub fn set(&mut self, parameter: Parameter, value: u32) {
        match parameter {
            Parameter::Resolution => self.resolution = value,
            Parameter::Grid => self.grid = value,
            Parameter::PoissonRatio => self.poisson_ratio = value,
            Parameter::Bulging => self.bulging = value,
            Parameter::LocalBlend => self.local_blend = value,
        }
    }

    /// The one check of the method's parameter ([`ParameterSpec::validate`]),
    /// for callers of the library as for the command line and the editor.
    pub fn validate(&self) -> Result<(), ParameterError> {
        if let Some((spec, value)) = self.parameter() {
            spec.validate(value.into())?;
        }
        for (spec, value) in self.deform_parameters() {
            spec.validate(value.into())?;
        }
        Ok(())
    }

    /// The settings this method reads when its weights deform a pose, with
    /// their values (Somigliana's bulging; none for the other families).
    pub fn deform_parameters(&self) -> impl Iterator<Item = (ParameterSpec, u32)> + '_ {
        (self.method.spec().deform_parameters.iter()).map(|spec| (*spec, self.get(spec.key)))
    }

    /// The deformation settings away from their defaults as titles say them
    /// ("γ 2.5"), so that a result names how it was deformed.
    pub fn deform_labels(&self) -> Vec<String> {
        (self.deform_parameters())
            .filter(|(spec, value)| *value != spec.default)
            .map(|(spec, value)| (spec.format)(value))
            .collect()
    }

    /// The parameter of this method and its value, if it has one.
    pub fn parameter(&self) -> Option<(ParameterSpec, u32)> {
        let spec = self.method.spec().parameter?;
        Some((spec, self.get(spec.key)))
    }

    /// Whether weights bound with `self` are the ones `other` asks for: the same
    /// method and the same values of the parameters that method reads.
    pub fn same_weights_as(&self, other: &BindOptions) -> bool {
        let key =
            |options: &BindOptions| options.parameter().map(|(spec, value)| (spec.key, value));
        self.method == other.method && key(self) == key(other) && self.quads == other.quads
    }

    /// The cage the family binds: `cage` itself, or a copy with its quads split
    /// into triangles when `--triangulate` asks for it or the family takes only
    /// triangles. Borrowed when nothing is split.
    pub fn cage_to_bind<'a>(&self, cage: &'a Cage) -> std::borrow::Cow<'a, Cage> {
        match self.split_applied(cage) {
            None => std::borrow::Cow::Borrowed(cage),
            Some(split) => std::borrow::Cow::Owned(cage.split_quads(split)),
        }
    }

    /// Where `points` lie for a bind with these options: classified against the
    /// cage the family binds ([`Self::cage_to_bind`]), not the cage as given.
    /// Where quads are split, their triangles decide inside and outside (a
    /// bilinear patch bulges past one of its two triangles), and a point on the
    /// surface is on the triangle the bind reads. Binds whose
    /// [`Self::split_applied`] agree share their classes.
    pub fn classify(&self, cage: &Cage, points: &[DVec3]) -> PointClasses {
        crate::geometry::classify_points(&self.cage_to_bind(cage), points)
    }

    /// Weights columns per point of a bind of `cage` with these options: the
    /// family's [`Method::columns`] of the cage it binds (Green's differ with
    /// the quads as patches or split).
    pub fn columns(&self, cage: &Cage) -> usize {
        self.method.columns(&self.cage_to_bind(cage))
    }

    /// How each weights column moves in `pose` ([`ColumnMoves`]) on the cage
    /// these options bind, with these options' deformation settings
    /// (Somigliana's bulging and local blend): [`Method::column_displacements`]
    /// for every linear family.
    pub fn column_moves(&self, cage: &Cage, pose: &[DVec3]) -> ColumnMoves {
        let bound = self.cage_to_bind(cage);
        if self.method == Method::Somigliana {
            return super::somigliana::column_moves(
                &bound,
                pose,
                self.poisson_ratio(),
                self.bulging(),
                self.local_blend(),
            );
        }
        ColumnMoves::linear(self.method.column_displacements(&bound, pose))
    }

    /// Whether [`Self::column_moves`] may be normalised (carry matrices) for
    /// some setting: Somigliana coordinates, with a local blend.
    pub fn moves_may_carry_matrices(&self) -> bool {
        self.method == Method::Somigliana
    }

    /// The Poisson ratio ν Somigliana coordinates bind with.
    pub fn poisson_ratio(&self) -> f64 {
        Parameter::PoissonRatio.spec().number(self.poisson_ratio)
    }

    /// The bulging γ Somigliana coordinates deform with.
    pub fn bulging(&self) -> f64 {
        Parameter::Bulging.spec().number(self.bulging)
    }

    /// The local/global blend Somigliana coordinates deform with (0: global).
    pub fn local_blend(&self) -> f64 {
        Parameter::LocalBlend.spec().number(self.local_blend)
    }

    /// Whether this is PMVC integrated exactly ([`EXACT_RESOLUTION`]).
    pub fn pmvc_exact(&self) -> bool {
        self.method == Method::Pmvc && self.resolution == EXACT_RESOLUTION
    }

    /// How the cage's quads are split for this bind, if they are (exact PMVC,
    /// like the cube map, takes them as bilinear patches).
    pub fn split_applied(&self, cage: &Cage) -> Option<QuadSplit> {
        if !cage.has_quads() {
            return None;
        }
        match (self.quads, self.method.spec().quads) {
            (QuadSplit::None, QuadSupport::Patches { .. }) => None,
            (QuadSplit::None, QuadSupport::Triangles) => Some(QuadSplit::Shorter),
            (split, _) => Some(split),
        }
    }

    /// The family's name for this cage: QMVC for MVC on bilinear quads, and
    /// "(shorter split)" or "(longer split)" after a family whose quads were split.
    pub fn family_name(&self, cage: &Cage) -> String {
        let spec = self.method.spec();
        match (self.split_applied(cage), spec.quads) {
            (None, QuadSupport::Patches { name }) if cage.has_quads() => name.to_owned(),
            (Some(split), QuadSupport::Patches { .. }) => {
                format!("{} ({} split)", spec.name, split.id())
            }
            _ => spec.name.to_owned(),
        }
    }

    /// What a user should know about the cage's quads in this bind, in one line:
    /// that they were split, and how, for a family that cannot take patches.
    pub fn quad_notice(&self, cage: &Cage) -> Option<String> {
        let split = self.split_applied(cage)?;
        let count = cage.quads().len();
        let spec = self.method.spec();
        Some(match spec.quads {
            QuadSupport::Triangles => format!(
                "notice: {} are bound on triangles: the cage's {count} quads were split along the {} diagonal ({})",
                spec.name,
                if split == QuadSplit::Longer { "longer" } else { "shorter" },
                spec.quads_reason
            ),
            QuadSupport::Patches { .. } => format!(
                "notice: the cage's {count} quads were split along the {} diagonal, as asked (--triangulate {})",
                split.id(),
                split.id()
            ),
        })
    }
}

impl Default for BindOptions {
    fn default() -> Self {
        Self {
            method: Method::Pmvc,
            resolution: DEFAULT_RESOLUTION,
            grid: harmonic::DEFAULT_GRID,
            poisson_ratio: Parameter::PoissonRatio.spec().default,
            bulging: Parameter::Bulging.spec().default,
            local_blend: Parameter::LocalBlend.spec().default,
            quads: QuadSplit::None,
        }
    }
}
