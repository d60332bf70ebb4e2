//! What a pane's colour bar says besides its scale: its title and its notes.

use crate::app::compare::Pane;
use crate::app::document::Document;
use crate::app::views::Views;
use crate::app::widgets::BarNote;
use crate::coords::Method;
use crate::render::Colouring;

impl Views {
    /// What the colour bar must also say: in the negativity view, that a family
    /// does not promise positive weights and how many vertices are outside the cage (grey,
    /// and why); for ψ, that it is signed or missing.
    pub(super) fn colour_bar_note(
        &self,
        document: &Document,
        colouring: Colouring,
        kind: Pane,
    ) -> Option<BarNote> {
        let outside = document.outside().len();
        let method = kind.method();
        let mut notes = Vec::new();
        // The grey swatch goes with the first line, so the outside count leads.
        let grey_swatch = colouring == Colouring::MostNegativeWeight && outside > 0;
        if grey_swatch {
            let policy = if method == Method::Green {
                "exterior extension"
            } else {
                "MVC"
            };
            notes.push(format!(
                "{outside} outside the cage ({policy} by policy), not counted"
            ));
        }
        if colouring == Colouring::MostNegativeWeight && !method.spec().positive_inside {
            notes.push(format!("{method} does not promise positive weights"));
        }
        if let Colouring::TriangleWeight(_) = colouring {
            let has_triangle_columns =
                method.columns(document.cage()) > method.vertex_columns(document.cage());
            let (_, symbol) = method.spec().columns.function_symbols();
            notes.push(if has_triangle_columns {
                format!("{symbol} is signed: blue below 0, red above")
            } else {
                format!("{method} has no {symbol}: shaded")
            });
        }
        (!notes.is_empty()).then(|| BarNote {
            text: notes.join("; "),
            grey_swatch,
        })
    }

    /// The bar's title, naming what was bound (QMVC for MVC on quads, "PMVC
    /// (shorter split)").
    pub(super) fn colour_bar_title(&self, document: &Document, kind: Pane) -> String {
        let method = document
            .bound(kind.method())
            .map_or(kind.method().name().to_owned(), |set| {
                set.options.family_name(document.cage())
            });
        let (vertex_symbol, triangle_symbol) = kind.method().spec().columns.function_symbols();
        match (self.settings.colouring(kind), kind) {
            (Colouring::CageVertexWeight(vertex), _) => {
                format!("{vertex_symbol}{vertex} ({method})")
            }
            (Colouring::TriangleWeight(triangle), _) => {
                match document.face_column(kind.method(), triangle as usize) {
                    Some(face) => format!("{triangle_symbol}{triangle} of {face} ({method})"),
                    None => format!("{triangle_symbol}{triangle} ({method})"),
                }
            }
            (Colouring::MostNegativeWeight, _) => format!("min {vertex_symbol} ({method})"),
            (Colouring::MethodDistance, Pane::Difference { .. }) => {
                // The pane's title names the methods; the bar says how it scales.
                match self.settings.difference_limit {
                    Some(_) => "distance / cage diagonal · fixed scale".to_owned(),
                    None => format!(
                        "distance / cage diagonal · auto, ≥ {}",
                        crate::app::widgets::percent(crate::app::compare::DIFFERENCE_FLOOR)
                    ),
                }
            }
            _ => String::new(),
        }
    }
}
