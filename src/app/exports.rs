//! Pictures and coloured meshes out of the editor: File > Save image… (the
//! viewport's panes as PNG, with their titles and colour bars) and File > Export
//! coloured mesh… (the deformed mesh as PLY, each vertex in the colour the view
//! gives it, with the scale and range in the header).

use super::compare::{self, Layout, Pane};
use super::document::Document;
use super::views::Views;
use crate::coords::Method;
use crate::formats::shown_path;
use crate::formats::{write_atomically, write_coloured_ply, WriteError};
use crate::render::colormap::{heat_colour, Scale, OUTSIDE};
use crate::render::Colouring;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// A Save image… waiting for the next frame's pixels, and what became of it.
#[derive(Default)]
pub struct ImageRequest {
    pending: Option<PathBuf>,
    /// Filled by the screenshot callback: the file written, or why not.
    finished: Arc<Mutex<Option<Result<PathBuf, String>>>>,
}

/// Write `image`, cropped to `crop` (in pixels), as PNG by the output rules.
pub fn save_png(
    path: &Path,
    image: &egui::ColorImage,
    crop: Option<[usize; 4]>,
) -> Result<(), WriteError> {
    let [width, height] = image.size;
    let [x0, y0, x1, y1] = crop.unwrap_or([0, 0, width, height]);
    let (x1, y1) = (x1.min(width), y1.min(height));
    let (x0, y0) = (x0.min(x1), y0.min(y1));
    let mut bytes = Vec::with_capacity((x1 - x0) * (y1 - y0) * 4);
    for row in y0..y1 {
        for pixel in &image.pixels[row * width + x0..row * width + x1] {
            bytes.extend_from_slice(&pixel.to_array());
        }
    }
    write_atomically(path, |out| {
        let mut encoded = std::io::Cursor::new(Vec::new());
        image::write_buffer_with_format(
            &mut encoded,
            &bytes,
            (x1 - x0) as u32,
            (y1 - y0) as u32,
            image::ColorType::Rgba8,
            image::ImageFormat::Png,
        )
        .map_err(std::io::Error::other)?;
        out.write_all(encoded.get_ref())
    })
}

impl ImageRequest {
    /// File > Save image…: the panes as drawn in the next frame.
    pub fn ask(&mut self, path: &Path) {
        self.pending = Some(path.to_owned());
    }

    /// Ask for the pixels of a pending Save image… cropped to `panes`, and
    /// return what became of an earlier one: the notice, or the error.
    pub fn drive(
        &mut self,
        ctx: &egui::Context,
        panes: impl Iterator<Item = egui::Rect>,
    ) -> Option<Result<String, String>> {
        let finished = self.finished.lock().ok().and_then(|mut slot| slot.take());
        let report =
            finished.map(|result| result.map(|path| format!("saved image {}", shown_path(&path))));
        let Some(path) = self.pending.take() else {
            return report;
        };
        let scale = ctx.pixels_per_point();
        let crop = panes.reduce(|a, b| a.union(b)).map(|rect| {
            [rect.left(), rect.top(), rect.right(), rect.bottom()]
                .map(|v| (v * scale).round().max(0.0) as usize)
        });
        let finished = Arc::clone(&self.finished);
        let repaint = ctx.clone();
        ctx.request_screenshot(move |image| {
            let result = save_png(&path, &image, crop)
                .map(|()| path.clone())
                .map_err(|error| error.to_string());
            if let Ok(mut slot) = finished.lock() {
                *slot = Some(result);
            }
            repaint.request_repaint();
        });
        ctx.request_repaint();
        report
    }
}

impl Views {
    /// The view a coloured export takes its colours from: the difference view in
    /// that layout, else the shown method's.
    fn exported_pane(&self, active: Method) -> Pane {
        match self.settings.layout {
            Layout::Difference => self.settings.difference_pane_kind(),
            _ => Pane::Method(active),
        }
    }

    /// File > Export coloured mesh…: the mesh deformed by the shown method, each
    /// vertex in the colour the view gives it (unlit), as PLY.
    pub fn export_coloured_mesh(
        &mut self,
        path: &Path,
        document: &Document,
        wanted: &[Method],
    ) -> Result<String, String> {
        super::files::refuse_overwriting_open_files(path, document)?;
        let pane = self.exported_pane(wanted[0]);
        let colouring = self.settings.colouring(pane);
        let Some(values) = self.vertex_values(document, colouring, pane) else {
            return Err(match colouring {
                Colouring::Shaded => {
                    "the mesh is plainly shaded: colour it by a heatmap, the negativity or \
                     the difference first"
                        .to_owned()
                }
                Colouring::TriangleWeight(_) if document.weights(pane.method()).is_some() => {
                    format!(
                        "{} has no per-triangle functions; only Green and Somigliana \
                         coordinates do",
                        pane.method()
                    )
                }
                _ => format!("{} is not bound yet", pane.method()),
            });
        };
        let limit = self.colour_limit(document, wanted, colouring, pane);
        let scale = self.settings.scale_of(colouring);
        let outside: std::collections::HashSet<u32> = document.outside().iter().copied().collect();
        let colours: Vec<[f32; 3]> = values
            .iter()
            .enumerate()
            .map(|(vertex, &value)| {
                if colouring == Colouring::MostNegativeWeight && outside.contains(&(vertex as u32))
                {
                    OUTSIDE
                } else {
                    heat_colour(value, limit, scale)
                }
            })
            .collect();
        let face = match colouring {
            Colouring::TriangleWeight(k) => document.face_column(pane.method(), k as usize),
            _ => None,
        };
        let comments = Self::colour_comments(colouring, pane, face, limit, scale);
        let positions = document.deformed_positions(pane.method());
        write_coloured_ply(
            path,
            &positions,
            &document.mesh().triangles,
            &colours,
            &comments,
        )
        .map_err(|error| error.to_string())?;
        Ok(format!("exported {}", shown_path(path)))
    }

    /// The value each mesh vertex is coloured by, as the vertex shader computes it.
    fn vertex_values(
        &mut self,
        document: &Document,
        colouring: Colouring,
        pane: Pane,
    ) -> Option<Vec<f32>> {
        match colouring {
            Colouring::Shaded => None,
            Colouring::CageVertexWeight(_) | Colouring::TriangleWeight(_) => {
                let weights = document.weights(pane.method())?;
                let column = shown_column(document, colouring, pane.method())?;
                (column < weights.cols)
                    .then(|| (0..weights.rows).map(|r| weights.row(r)[column]).collect())
            }
            Colouring::MostNegativeWeight => {
                let weights = document.weights(pane.method())?;
                let columns = (pane.method().vertex_columns(document.cage())).min(weights.cols);
                let stride = pane.method().spec().columns.columns_per_element();
                Some(
                    (0..weights.rows)
                        .map(|r| {
                            weights.row(r)[..columns]
                                .iter()
                                .step_by(stride)
                                .copied()
                                .fold(f32::INFINITY, f32::min)
                        })
                        .collect(),
                )
            }
            Colouring::MethodDistance => {
                let Pane::Difference { against, shown } = pane else {
                    return None;
                };
                let a = self.deformed_on_cpu(document, against)?;
                let b = self.deformed_on_cpu(document, shown)?;
                let size = compare::cage_size(document.cage().positions()) as f32;
                Some(
                    b.iter()
                        .zip(a.iter())
                        .map(|(p, q)| (*p - *q).length() / size.max(1e-30))
                        .collect(),
                )
            }
        }
    }

    fn colour_comments(
        colouring: Colouring,
        pane: Pane,
        face: Option<crate::coords::green::FaceColumn>,
        limit: f32,
        scale: Scale,
    ) -> Vec<String> {
        let blocks = pane.method().spec().columns.columns_per_element() > 1;
        let what = match (colouring, pane) {
            (Colouring::CageVertexWeight(vertex), _) if blocks => {
                format!("{} block of cage vertex {vertex}, entry xx", pane.method())
            }
            (Colouring::CageVertexWeight(vertex), _) => {
                format!("{} coordinate of cage vertex {vertex}", pane.method())
            }
            (Colouring::TriangleWeight(triangle), _) if blocks => {
                format!(
                    "{} block of cage triangle {triangle}, entry xx",
                    pane.method()
                )
            }
            (Colouring::TriangleWeight(column), _) => match face {
                Some(face) => format!("{} psi {column}, of cage {face}", pane.method()),
                None => format!("{} psi {column}", pane.method()),
            },
            (Colouring::MostNegativeWeight, _) => {
                format!("{} most negative weight per vertex", pane.method())
            }
            (_, Pane::Difference { against, shown }) => {
                format!("distance between the {shown} and {against} deformations / cage diagonal")
            }
            _ => "plain shading".into(),
        };
        let scale = match scale {
            Scale::Linear => "linear scale".to_owned(),
            Scale::LogMagnitude => format!(
                "log scale over {} decades below the limit",
                crate::render::colormap::LOG_DECADES
            ),
        };
        let mut comments = vec![
            format!("colours: {what}"),
            format!(
                "colour scale: blue -{limit:.6} .. white 0 .. red +{limit:.6}, {scale}; values beyond saturate"
            ),
            format!("positions: the mesh deformed with {}", pane.method()),
        ];
        if colouring == Colouring::MostNegativeWeight {
            comments.push(
                "grey vertices are outside the cage: their weights follow the outside policy"
                    .into(),
            );
        }
        comments
    }
}

/// The weights column a heatmap of `colouring` shows for `method`, as the
/// vertex shader picks it (`Colouring::code`); `None` for other colourings and
/// for a triangle's function in a family without triangle columns.
pub(super) fn shown_column(
    document: &Document,
    colouring: Colouring,
    method: crate::coords::Method,
) -> Option<usize> {
    let layout = method.spec().columns;
    match colouring {
        Colouring::CageVertexWeight(vertex) => Some(layout.vertex_function_column(vertex as usize)),
        Colouring::TriangleWeight(triangle) => {
            layout.triangle_function_column(document.cage().vertex_count(), triangle as usize)
        }
        _ => None,
    }
}
