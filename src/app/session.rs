//! Sessions: a small JSON file that brings back a piece of work. It names the
//! mesh and cage (files relative to the session, or a bundled scene), holds the
//! rest cage when it was edited, the pose, the named poses, the method and its
//! parameters, and the view settings with the cameras.
//!
//! A rest mesh that no longer matches its source ("Use pose as rest shape") is
//! written beside the session as `NAME.rest-mesh.obj`, so the session stays small.

use super::compare::{saturating_f32, ViewSettings};
use super::document::{Document, NamedPose};
use super::scenes::BundledScene;
use super::session_checks::{
    camera_in_range, checked_pose, cut_text, inline_cage_defect, view_in_range, Reach,
    SESSION_SIZE_LIMIT,
};
use super::session_paths::{folder_of, session_folder};
use crate::budget::read_limited;
use crate::coords::{BindOptions, Method, Parameter, ParameterError, QuadSplit};
use crate::formats::{
    load_cage_object, load_mesh_object, not_a_regular_file, refuse_same_file, shown_path,
    write_atomically, write_deformed_mesh, write_obj, CageLoadError, FileObjects, LoadError,
    MeshFile, WriteError,
};
use crate::geometry::{Cage, TriMesh};
use crate::render::{OrbitCamera, SceneOrigin};
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The format version this editor writes and reads.
pub const SESSION_VERSION: u32 = 1;

/// Where the mesh comes from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MeshSource {
    /// A bundled scene's mesh, by its id ("comb").
    Bundled(String),
    /// A file, relative to the session's folder.
    File(PathBuf),
}

/// Where the rest cage comes from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CageSource {
    Bundled(String),
    File(PathBuf),
    /// An edited cage (subdivided, rested in a pose), written out in full.
    Inline {
        positions: Vec<[f64; 3]>,
        triangles: Vec<[u32; 3]>,
        /// The faces as polygons, when the cage has quads: they are read
        /// instead of `triangles`, so the quads stay bilinear patches.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        faces: Option<Vec<Vec<u32>>>,
    },
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct NamedPoseEntry {
    pub name: String,
    pub positions: Vec<[f64; 3]>,
    /// Its time on the timeline, in seconds, when it is on it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time: Option<f64>,
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CameraEntry {
    /// World coordinates, in f64: a scene far from the origin keeps its view.
    pub target: [f64; 3],
    #[serde(deserialize_with = "saturating_f32")]
    pub distance: f32,
    #[serde(deserialize_with = "saturating_f32")]
    pub yaw: f32,
    #[serde(deserialize_with = "saturating_f32")]
    pub pitch: f32,
    /// A parallel view (numpad 5); absent in sessions from before it existed.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub orthographic: bool,
}

/// A session file as written.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SessionFile {
    /// [`SESSION_VERSION`]; also what marks the file as a pmvc session.
    pub pmvc_session: u32,
    pub title: String,
    pub mesh: MeshSource,
    pub cage: CageSource,
    /// The object of the mesh file that is the mesh, where one was chosen by
    /// name (absent: the file's default, as in sessions from before).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mesh_object: Option<String>,
    /// The object of the cage file that is the cage, where one was chosen.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cage_object: Option<String>,
    /// One position per cage vertex.
    pub pose: Vec<[f64; 3]>,
    #[serde(default)]
    pub named_poses: Vec<NamedPoseEntry>,
    /// The method a single view shows.
    pub method: Method,
    /// Each family's parameter by name ("resolution": 32).
    #[serde(default, with = "crate::coords::parameter_values")]
    pub parameters: BTreeMap<String, u64>,
    /// How the cage's quads are bound: "none" (bilinear patches, the default and
    /// what sessions from before this setting get), "shorter" or "longer".
    #[serde(default, skip_serializing_if = "is_no_split")]
    pub triangulate: QuadSplit,
    #[serde(default)]
    pub view: ViewSettings,
    /// One camera per view (the first is every view's while they are locked).
    #[serde(default)]
    pub cameras: Vec<CameraEntry>,
}

/// A session could not be read or written; each message names the file.
#[derive(Debug, thiserror::Error)]
pub enum SessionError {
    #[error("{path}: cannot read: {source}", path = shown_path(path))]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: line {line}, column {column}: {message}", path = shown_path(path))]
    Parse {
        path: PathBuf,
        line: usize,
        column: usize,
        message: String,
    },
    #[error("{path}: a session of format {found}; this editor reads format {SESSION_VERSION}", path = shown_path(path))]
    Version { path: PathBuf, found: u32 },
    #[error("{path}: no bundled scene is called \"{id}\"", path = shown_path(path))]
    UnknownScene { path: PathBuf, id: String },
    #[error("{path}: the edited cage it holds (\"cage\": {{\"inline\": …}}): {message}", path = shown_path(path))]
    InlineCage { path: PathBuf, message: String },
    #[error("{path}: {what} has {found} positions but the cage has {expected} vertices", path = shown_path(path))]
    PoseLength {
        path: PathBuf,
        what: String,
        found: usize,
        expected: usize,
    },
    #[error("{path}: {what} has a coordinate that is not a finite number", path = shown_path(path))]
    NonFinite { path: PathBuf, what: String },
    #[error("{path}: {what}: {message}", path = shown_path(path))]
    BeyondReach {
        path: PathBuf,
        what: String,
        message: String,
    },
    #[error("{path}: \"parameters\": {source}", path = shown_path(path))]
    Parameter {
        path: PathBuf,
        source: ParameterError,
    },
    #[error("{path}: the mesh: {source}", path = shown_path(path))]
    Mesh { path: PathBuf, source: LoadError },
    #[error("{path}: the cage: {source}", path = shown_path(path))]
    Cage {
        path: PathBuf,
        source: CageLoadError,
    },
    #[error(transparent)]
    Write(#[from] WriteError),
    #[error("{path}: cannot encode the session: {message}", path = shown_path(path))]
    Encode { path: PathBuf, message: String },
}

/// What the editor keeps besides the document: the method, parameters and views.
#[derive(Clone, Debug)]
pub struct SessionSettings {
    pub bind_options: BindOptions,
    pub view: ViewSettings,
    /// In the scene coordinates the editor draws the document in
    /// ([`SceneOrigin::of_cage`] of its rest cage); files hold world ones.
    pub cameras: Vec<OrbitCamera>,
}

/// A session read back: the document to open, and the settings to apply.
pub struct OpenedSession {
    pub document: Document,
    pub settings: SessionSettings,
    /// Things worth saying that did not stop the session from opening.
    pub notes: Vec<String>,
}

fn is_no_split(split: &QuadSplit) -> bool {
    *split == QuadSplit::None
}

fn to_array(p: DVec3) -> [f64; 3] {
    p.to_array()
}

pub(super) fn to_points(points: &[[f64; 3]]) -> Vec<DVec3> {
    points.iter().map(|&p| DVec3::from_array(p)).collect()
}

/// `path` written relative to `folder` when it is inside it, else absolute.
fn relative_to(path: &Path, folder: &Path) -> PathBuf {
    let absolute = std::path::absolute(path).unwrap_or_else(|_| path.to_owned());
    let folder = std::path::absolute(folder).unwrap_or_else(|_| folder.to_owned());
    absolute
        .strip_prefix(&folder)
        .map(Path::to_owned)
        .unwrap_or(absolute)
}

/// The mesh and cage files a session names, read as loosely as can be: what a
/// run must not overwrite even when the session then fails to open.
pub fn files_named(path: &Path) -> Vec<PathBuf> {
    if not_a_regular_file(path).is_some() {
        return Vec::new();
    }
    let Ok(bytes) = read_limited(path, SESSION_SIZE_LIMIT) else {
        return Vec::new();
    };
    let text = bytes.strip_prefix("\u{feff}".as_bytes()).unwrap_or(&bytes);
    let Ok(session) = serde_json::from_slice::<serde_json::Value>(text) else {
        return Vec::new();
    };
    let folder = session_folder(path, &mut |_| {});
    ["mesh", "cage"]
        .iter()
        .filter_map(|key| session[key]["file"].as_str())
        .map(|file| folder.join(file))
        .collect()
}

/// Where a session saved as `session` keeps a rest mesh that changed.
pub fn rest_mesh_path(session: &Path) -> PathBuf {
    let name = session
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "session".into());
    let stem = name
        .strip_suffix(".json")
        .unwrap_or(&name)
        .trim_end_matches(".session");
    session.with_file_name(format!("{stem}.rest-mesh.obj"))
}

/// Write `document` and `settings` as a session at `path` (through a temporary
/// file, by the output rules). A rest mesh that differs from its source is
/// written beside it first.
pub fn save_session(
    path: &Path,
    document: &Document,
    settings: &SessionSettings,
) -> Result<(), SessionError> {
    let folder = folder_of(path);
    let (mesh, mesh_object) = mesh_source(path, &folder, document)?;
    let (cage, cage_object) = cage_source(&folder, document);
    let origin = SceneOrigin::of_cage(document.cage().positions());
    let session = SessionFile {
        pmvc_session: SESSION_VERSION,
        title: document.title().to_owned(),
        mesh,
        cage,
        mesh_object,
        cage_object,
        pose: document.pose().iter().copied().map(to_array).collect(),
        named_poses: document
            .named_poses()
            .iter()
            .map(|named| NamedPoseEntry {
                name: named.name.clone(),
                positions: named.positions.iter().copied().map(to_array).collect(),
                time: named.time,
            })
            .collect(),
        method: settings.bind_options.method,
        parameters: Parameter::ALL
            .into_iter()
            .map(|p| {
                let value = match p.read_when_deforming() {
                    true => document.deform_value(p),
                    false => settings.bind_options.get(p),
                };
                (p.id().to_owned(), value.into())
            })
            .collect(),
        triangulate: settings.bind_options.quads,
        view: settings.view,
        cameras: settings
            .cameras
            .iter()
            .map(|camera| CameraEntry {
                target: origin.to_world(camera.target).to_array(),
                distance: camera.distance,
                yaw: camera.yaw,
                pitch: camera.pitch,
                orthographic: camera.orthographic,
            })
            .collect(),
    };
    let text = serde_json::to_string_pretty(&session).map_err(|error| SessionError::Encode {
        path: path.to_owned(),
        message: error.to_string(),
    })?;
    let text = super::session_json::one_point_per_line(&text);
    write_atomically(path, |out| out.write_all(text.as_bytes()))?;
    Ok(())
}

fn mesh_source(
    session: &Path,
    folder: &Path,
    document: &Document,
) -> Result<(MeshSource, Option<String>), SessionError> {
    if let Some(scene) = document.bundled() {
        return Ok((MeshSource::Bundled(scene.id().to_owned()), None));
    }
    let positions = &document.mesh().positions;
    if let Some(file) = document.mesh_file() {
        if &file.mesh.positions == positions {
            let source = MeshSource::File(relative_to(&file.path, folder));
            return Ok((source, file.objects.read.clone()));
        }
    }
    // The mesh rests elsewhere than any file says: keep it beside the session.
    let sidecar = rest_mesh_path(session);
    let mut inputs: Vec<&Path> = document
        .mesh_file()
        .map(|f| f.path.as_path())
        .into_iter()
        .collect();
    inputs.extend(document.cage_path());
    refuse_same_file(&sidecar, &inputs)?;
    match document.mesh_file() {
        Some(file) => write_deformed_mesh(file, positions, &sidecar).map(drop)?,
        None => write_obj(&sidecar, document.mesh())?,
    }
    // The sidecar holds the one object written.
    Ok((MeshSource::File(relative_to(&sidecar, folder)), None))
}

/// Where the rest cage comes from, and which object of its file it is.
fn cage_source(folder: &Path, document: &Document) -> (CageSource, Option<String>) {
    let cage = document.cage();
    let same = |other: &Cage| {
        other.positions() == cage.positions() && other.triangles() == cage.triangles()
    };
    if let Some(scene) = document.bundled() {
        if scene.build().is_ok_and(|(_, bundled)| same(&bundled)) {
            return (CageSource::Bundled(scene.id().to_owned()), None);
        }
    }
    if let Some(path) = document.cage_path() {
        let object = document.cage_objects().read.clone();
        if load_cage_object(path, object.as_deref()).is_ok_and(|(file_cage, ..)| same(&file_cage)) {
            return (CageSource::File(relative_to(path, folder)), object);
        }
    }
    let inline = CageSource::Inline {
        positions: cage.positions().iter().copied().map(to_array).collect(),
        triangles: cage.triangles().to_vec(),
        faces: cage.has_quads().then(|| cage.polygons()),
    };
    (inline, None)
}

/// Read the session at `path` and everything it names. Nothing is changed on
/// failure; the error names the file and what is wrong. The file is read up to
/// [`SESSION_SIZE_LIMIT`]; a UTF-8 byte-order mark before it is skipped.
pub fn open_session(path: &Path) -> Result<OpenedSession, SessionError> {
    // A session's relative paths need a folder, and a named pipe with no
    // writer would wait forever.
    if let Some(kind) = not_a_regular_file(path) {
        return Err(SessionError::Read {
            path: path.to_owned(),
            source: std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                format!("it is {kind}, not a session file"),
            ),
        });
    }
    let bytes = read_limited(path, SESSION_SIZE_LIMIT).map_err(|source| SessionError::Read {
        path: path.to_owned(),
        source,
    })?;
    let text = bytes.strip_prefix("\u{feff}".as_bytes()).unwrap_or(&bytes);
    let session: SessionFile = serde_json::from_slice(text).map_err(|error| {
        // serde_json counts lines and columns from 1, as editors do.
        let message = error.to_string();
        let message = message
            .rsplit_once(" at line ")
            .map_or(message.as_str(), |(head, _)| head);
        // It may quote a whole value of the file (a string of millions of characters).
        let message = match cut_text(message, "") {
            (kept, Some(_)) => kept + "…",
            (kept, None) => kept,
        };
        SessionError::Parse {
            path: path.to_owned(),
            line: error.line(),
            column: error.column(),
            message,
        }
    })?;
    if session.pmvc_session != SESSION_VERSION {
        return Err(SessionError::Version {
            path: path.to_owned(),
            found: session.pmvc_session,
        });
    }
    let mut notes = Vec::new();
    let mut note = |text: String| notes.push(format!("{}: {text}", shown_path(path)));
    let folder = session_folder(path, &mut note);
    let scene = |id: &str| {
        BundledScene::from_id(id).ok_or_else(|| SessionError::UnknownScene {
            path: path.to_owned(),
            id: id.to_owned(),
        })
    };
    let cage_error = |source| SessionError::Cage {
        path: path.to_owned(),
        source,
    };
    let (title, cut) = cut_text(&session.title, "the title");
    cut.into_iter().for_each(&mut note);
    let mut bind_options = BindOptions::for_method(session.method);
    bind_options.quads = session.triangulate;
    for (name, &value) in &session.parameters {
        match Parameter::ALL.into_iter().find(|p| p.id() == name) {
            Some(parameter) => {
                let value =
                    parameter
                        .validate(value)
                        .map_err(|source| SessionError::Parameter {
                            path: path.to_owned(),
                            source,
                        })?;
                bind_options.set(parameter, value);
            }
            None => note(format!("ignored the unknown parameter \"{name}\"")),
        }
    }
    let (mesh, mesh_file, bundled_mesh): (TriMesh, Option<MeshFile>, Option<BundledScene>) =
        match &session.mesh {
            MeshSource::Bundled(id) => {
                let bundled = scene(id)?;
                (bundled.build().map_err(cage_error)?.0, None, Some(bundled))
            }
            MeshSource::File(file) => {
                let object = session.mesh_object.as_deref();
                let file = load_mesh_object(&folder.join(file), object).map_err(|source| {
                    SessionError::Mesh {
                        path: path.to_owned(),
                        source,
                    }
                })?;
                (file.mesh.clone(), Some(file), None)
            }
        };
    let mut cage_objects = FileObjects::default();
    let (cage, cage_path) = match &session.cage {
        CageSource::Bundled(id) => (scene(id)?.build().map_err(cage_error)?.1, None),
        CageSource::File(file) => {
            let cage_path = folder.join(file);
            let object = session.cage_object.as_deref();
            let (cage, report, read) = load_cage_object(&cage_path, object).map_err(cage_error)?;
            report.messages().into_iter().for_each(&mut note);
            cage_objects = read.objects;
            (cage, Some(cage_path))
        }
        CageSource::Inline {
            positions,
            triangles,
            faces,
        } => {
            let mesh = match faces {
                Some(faces) => crate::geometry::triangulate_faces(faces, &to_points(positions)),
                None => TriMesh {
                    positions: to_points(positions),
                    triangle_faces: (0..triangles.len() as u32).collect(),
                    triangles: triangles.clone(),
                },
            };
            let (cage, report) = Cage::new(mesh).map_err(|error| SessionError::InlineCage {
                path: path.to_owned(),
                message: inline_cage_defect(&error),
            })?;
            report.messages().into_iter().for_each(&mut note);
            (cage, None)
        }
    };
    let reach = Reach::of(cage.positions());
    let origin = SceneOrigin::of_cage(cage.positions());
    let check = |what: String, points: &[[f64; 3]]| {
        checked_pose(path, what, points, cage.vertex_count(), &reach)
    };
    let pose = check("the pose".into(), &session.pose)?;
    let mut named_poses = Vec::new();
    for (index, named) in session.named_poses.iter().enumerate() {
        let number = index + 1;
        let (name, cut) = cut_text(&named.name, &format!("the name of named pose {number}"));
        cut.into_iter().for_each(&mut note);
        let what = format!("named pose {number} ({name:?})");
        // A time out of range takes the pose off the timeline, with a note.
        let time = named.time.and_then(|seconds| {
            crate::app::timeline::check_key_time(seconds)
                .map_err(|why| note(format!("{what}: {why}; it is left off the timeline")))
                .ok()
        });
        named_poses.push(NamedPose {
            name,
            positions: check(what, &named.positions)?,
            time,
        });
    }
    let mut view_notes = Vec::new();
    let view = view_in_range(
        session.view,
        cage.vertex_count(),
        cage.triangle_count(),
        &mut view_notes,
    );
    let cameras = session
        .cameras
        .iter()
        .enumerate()
        .map(|(index, entry)| camera_in_range(entry, index, &reach, origin, &mut view_notes))
        .collect();
    view_notes.into_iter().for_each(&mut note);

    let mut document = Document::new(title, mesh, cage)
        .with_files(mesh_file, cage_path)
        .with_cage_objects(cage_objects)
        .with_poses(pose, named_poses)
        .with_deform_values(
            (Parameter::ALL.into_iter())
                .filter(|p| p.read_when_deforming())
                .map(|p| (p, bind_options.get(p))),
        );
    if let Some(bundled) = bundled_mesh {
        document = document.bundled_as(bundled);
    }
    Ok(OpenedSession {
        document,
        settings: SessionSettings {
            bind_options,
            view,
            cameras,
        },
        notes,
    })
}

/// `session`'s view settings with every setting that `asked` changes from the
/// default put over them: options given on the command line beside `--session`
/// win, the rest comes from the session. New settings need no code here.
pub fn view_with_overrides(session: ViewSettings, asked: ViewSettings) -> ViewSettings {
    let to_map = |view: &ViewSettings| match serde_json::to_value(view) {
        Ok(serde_json::Value::Object(map)) => Some(map),
        _ => None,
    };
    let (Some(mut merged), Some(asked_map), Some(default)) = (
        to_map(&session),
        to_map(&asked),
        to_map(&ViewSettings::default()),
    ) else {
        return session;
    };
    for (key, value) in asked_map {
        if default.get(&key) != Some(&value) {
            merged.insert(key, value);
        }
    }
    serde_json::from_value(serde_json::Value::Object(merged)).unwrap_or(session)
}
