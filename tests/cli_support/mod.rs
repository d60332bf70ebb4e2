//! Helpers shared by the command-line tests of `.npy` point sets and weights
//! metadata: hand-written `.npy` files, the comb scene's poses, and `pmvc bind`
//! and `pmvc deform` on the CPU.
#![allow(dead_code)]

use crate::common::*;
use glam::DVec3;
use pmvc::geometry::Cage;
use std::path::{Path, PathBuf};

/// A version 1.0 `.npy` with this dtype, shape and raw little-endian values,
/// written by hand as NumPy's `np.save` writes it.
pub fn npy_bytes(descr: &str, shape: &[usize], fortran: bool, values: &[u8]) -> Vec<u8> {
    let shape_text = match shape {
        [one] => format!("({one},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    let order = if fortran { "True" } else { "False" };
    let mut header =
        format!("{{'descr': '{descr}', 'fortran_order': {order}, 'shape': {shape_text}, }}");
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend_from_slice(&(header.len() as u16).to_le_bytes());
    bytes.extend_from_slice(header.as_bytes());
    bytes.extend_from_slice(values);
    bytes
}

pub fn f64_points_npy(points: &[DVec3]) -> Vec<u8> {
    let values: Vec<u8> = points
        .iter()
        .flat_map(|p| p.to_array())
        .flat_map(f64::to_le_bytes)
        .collect();
    npy_bytes("<f8", &[points.len(), 3], false, &values)
}

pub fn f32_points_npy(points: &[DVec3]) -> Vec<u8> {
    let values: Vec<u8> = points
        .iter()
        .flat_map(|p| p.to_array())
        .flat_map(|v| (v as f32).to_le_bytes())
        .collect();
    npy_bytes("<f4", &[points.len(), 3], false, &values)
}

/// `(n, 3)` float64 points from a `.npy`, parsed by hand.
pub fn read_points_f64(path: &Path) -> Vec<DVec3> {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(&bytes[..8], b"\x93NUMPY\x01\x00");
    let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let header = std::str::from_utf8(&bytes[10..10 + header_len]).unwrap();
    assert!(header.contains("'descr': '<f8'"), "{header}");
    assert!(header.contains("'fortran_order': False"), "{header}");
    let values: Vec<f64> = bytes[10 + header_len..]
        .chunks(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect();
    let rows = values.len() / 3;
    assert!(
        header.contains(&format!("'shape': ({rows}, 3)")),
        "{header}"
    );
    values
        .chunks(3)
        .map(|v| DVec3::new(v[0], v[1], v[2]))
        .collect()
}

/// The `v` lines of an OBJ file.
pub fn obj_vertices(path: &Path) -> Vec<DVec3> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter_map(|line| line.strip_prefix("v "))
        .map(|rest| {
            let v: Vec<f64> = rest
                .split_whitespace()
                .map(|t| t.parse().unwrap())
                .collect();
            DVec3::new(v[0], v[1], v[2])
        })
        .collect()
}

pub fn bind(
    mesh: &Path,
    cage: &Path,
    method: &str,
    out: &Path,
    extra: &[&str],
) -> std::process::Output {
    let mut args = vec!["--method", method];
    args.extend_from_slice(extra);
    bind_on_cpu(mesh, cage, out, &args)
}

/// `pmvc deform` on the CPU, then `extra`.
pub fn deform(
    mesh: &Path,
    cage: &Path,
    pose: &Path,
    out: &Path,
    extra: &[&str],
) -> std::process::Output {
    let mut args = vec!["--backend", "cpu"];
    args.extend_from_slice(extra);
    deform_with(mesh, cage, pose, out, &args)
}

/// The comb of `comb_scene` with its second tooth's tip moved `shift` along x.
pub fn comb_pose(cage: &Cage, shift: f64) -> Vec<DVec3> {
    cage.positions()
        .iter()
        .map(|&p| {
            let second_tooth = (1.25..=2.25).contains(&p.x) && p.y > 3.9;
            if second_tooth {
                p + DVec3::new(shift, 0.0, 0.0)
            } else {
                p
            }
        })
        .collect()
}

/// Points in the comb and two beyond its surface.
pub fn partly_outside(dir: &Path) -> (PathBuf, PathBuf, Cage, Vec<DVec3>) {
    let (_, cage_path, cage, mut points) = comb_scene(dir, 30);
    points.push(DVec3::new(1.125, 2.5, 0.0)); // in the gap between two teeth
    points.push(DVec3::new(2.0, -3.0, 4.0));
    let mesh = write(dir, "outside.obj", &points_obj(&points));
    (mesh, cage_path, cage, points)
}
