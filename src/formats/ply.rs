//! PLY output: a triangle mesh with one colour per vertex (ASCII, which every
//! mesh tool reads), with comments that say what the colours mean.

use super::error::WriteError;
use super::output::write_atomically;
use glam::DVec3;
use std::io::Write;
use std::path::Path;

/// Write `positions` and `triangles` with 8-bit `colours` (components in [0, 1],
/// one per vertex) and a `comment` line for each of `comments`.
pub fn write_coloured_ply(
    path: &Path,
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    colours: &[[f32; 3]],
    comments: &[String],
) -> Result<(), WriteError> {
    write_atomically(path, |out| {
        write_coloured_ply_to(out, positions, triangles, colours, comments)
    })
}

/// A colour component as the byte PLY stores: rounded, clamped to 0–255.
pub fn colour_byte(component: f32) -> u8 {
    (component.clamp(0.0, 1.0) * 255.0).round() as u8
}

fn write_coloured_ply_to(
    out: &mut dyn Write,
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    colours: &[[f32; 3]],
    comments: &[String],
) -> std::io::Result<()> {
    if colours.len() != positions.len() {
        return Err(std::io::Error::other(format!(
            "{} colours for {} vertices",
            colours.len(),
            positions.len()
        )));
    }
    writeln!(out, "ply\nformat ascii 1.0\ncomment written by pmvc")?;
    for comment in comments {
        // A line break would end the comment and corrupt the header.
        writeln!(out, "comment {}", comment.replace(['\n', '\r'], " "))?;
    }
    writeln!(out, "element vertex {}", positions.len())?;
    writeln!(
        out,
        "property double x\nproperty double y\nproperty double z"
    )?;
    writeln!(
        out,
        "property uchar red\nproperty uchar green\nproperty uchar blue"
    )?;
    writeln!(out, "element face {}", triangles.len())?;
    writeln!(out, "property list uchar int vertex_indices\nend_header")?;
    for (p, c) in positions.iter().zip(colours) {
        let [r, g, b] = c.map(colour_byte);
        writeln!(out, "{:?} {:?} {:?} {r} {g} {b}", p.x, p.y, p.z)?;
    }
    for [a, b, c] in triangles {
        writeln!(out, "3 {a} {b} {c}")?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_header_counts_what_follows_and_colours_round_to_bytes() {
        let mut out = Vec::new();
        let positions = [DVec3::ZERO, DVec3::X, DVec3::new(0.0, 0.1, 1e-20)];
        let colours = [[0.0, 0.5, 1.0], [1.5, -0.2, 0.502], [0.97, 0.97, 0.97]];
        write_coloured_ply_to(
            &mut out,
            &positions,
            &[[0, 1, 2]],
            &colours,
            &["λ of cage vertex 3\nsecond line".into()],
        )
        .unwrap();
        let text = String::from_utf8(out).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        let end = lines.iter().position(|l| *l == "end_header").unwrap();
        assert!(lines.contains(&"comment λ of cage vertex 3 second line"));
        assert!(lines.contains(&"element vertex 3"));
        assert!(lines.contains(&"element face 1"));
        assert_eq!(lines[end + 1], "0.0 0.0 0.0 0 128 255");
        assert_eq!(lines[end + 2], "1.0 0.0 0.0 255 0 128");
        // f64 positions round-trip.
        let z: f64 = lines[end + 3].split(' ').nth(2).unwrap().parse().unwrap();
        assert_eq!(z, 1e-20);
        assert_eq!(lines[end + 4], "3 0 1 2");
        assert_eq!(lines.len(), end + 5);
    }

    #[test]
    fn a_colour_count_that_does_not_match_is_an_error_not_a_short_file() {
        let mut out = Vec::new();
        let result = write_coloured_ply_to(&mut out, &[DVec3::ZERO], &[], &[], &[]);
        assert!(result.is_err());
    }
}
