//! How a PMVC bind integrates the visible cage around a point: over a cube map
//! of a given resolution (the paper's method), or exactly
//! ([`crate::coords::exact_pmvc`]), chosen by the resolution parameter.

use super::{pmvc_weights_inside, PmvcScratch};
use crate::coords::cubemap::TexelTable;
use crate::coords::exact_pmvc::exact_pmvc_weights_inside;
use crate::coords::{BindOptions, EXACT_RESOLUTION};
use crate::geometry::Cage;
use glam::DVec3;

/// PMVC's integration for one bind, set up once and shared by its rows.
#[derive(Debug)]
pub enum PmvcIntegration {
    /// Rays through the texels of a cube map of this table's resolution.
    CubeMap(TexelTable),
    /// The visible fragments of every triangle, in closed form.
    Exact,
}

impl PmvcIntegration {
    /// The integration `options` ask for; a cube map's table is only built
    /// for PMVC (the other families read none).
    pub fn of(options: BindOptions) -> Self {
        match options.method {
            crate::coords::Method::Pmvc if options.resolution != EXACT_RESOLUTION => {
                Self::CubeMap(TexelTable::new(options.resolution))
            }
            _ => Self::Exact,
        }
    }

    /// PMVC of `x`, strictly inside `cage`, into `out`; false when a ray
    /// escapes or the visible cage does not cover the sphere around `x` (the
    /// point is not enclosed after all: the caller follows the outside policy).
    pub fn weights_inside(
        &self,
        x: DVec3,
        cage: &Cage,
        out: &mut [f64],
        scratch: &mut PmvcScratch,
    ) -> bool {
        match self {
            Self::CubeMap(table) => pmvc_weights_inside(x, cage, table, out, scratch),
            Self::Exact => exact_pmvc_weights_inside(x, cage, out, &mut scratch.exact).is_ok(),
        }
    }
}
