//! File actions as values: reading what opening a mesh, a cage, a pair, a
//! session or a bundled scene brings, and what editing the cage makes, each as a
//! [`SceneChange`] the editor then makes (one undo step, a bind); and writing
//! poses and deformed meshes. Nothing here touches the editor: a file that fails
//! to load or validate is an error message, and the scene stays as it was.

use super::actions::FileRole;
use super::cage_generation::{cage_reaches, loose_box_cage, Proposal};
use super::compare::ViewSettings;
use super::document::Document;
pub use super::file_objects::ObjectNames;
use super::file_objects::{object_note, recent_file};
use super::recent::RecentEntry;
use super::scenes::BundledScene;
use super::session::{self, SessionSettings};
use crate::coords::{BindOptions, Method};
use crate::formats::shown_path;
use crate::formats::{
    load_cage_object, load_mesh_object, refuse_same_file, write_atomically, write_cage_and_pose,
    write_deformed_mesh, write_mesh_with_normals, write_polygons_obj_to, MeshFile,
};
use crate::geometry::{polygons_of, subdivide_midpoint, TriMesh};
use crate::render::OrbitCamera;
use glam::DVec3;
use std::path::{Path, PathBuf};

pub(super) fn file_title(path: &Path) -> String {
    path.file_name()
        .map_or_else(|| "mesh".into(), |n| n.to_string_lossy().into_owned())
}

/// Where the cameras go when the document is replaced.
pub(super) enum Cameras {
    /// Frame the new document.
    Frame,
    /// Stay where they are (a cage edit on the same mesh).
    Keep,
    /// A session's cameras.
    Session(Vec<OrbitCamera>),
}

/// A whole-document replacement and what comes with it.
pub(super) struct Replacement {
    pub document: Document,
    /// What undo calls it ("open cage.obj").
    pub action: String,
    pub cameras: Cameras,
    /// A session's bind options and view settings.
    pub settings: Option<(BindOptions, ViewSettings)>,
}

impl Replacement {
    /// `document` replacing the current one by `action`, framed.
    pub(super) fn framed(document: Document, action: impl Into<String>) -> Self {
        Self {
            document,
            action: action.into(),
            cameras: Cameras::Frame,
            settings: None,
        }
    }

    /// `document` replacing the current one by `action`, the cameras kept.
    pub(super) fn in_place(document: Document, action: impl Into<String>) -> Self {
        Self {
            cameras: Cameras::Keep,
            ..Self::framed(document, action)
        }
    }
}

/// A new document and what comes with it.
pub struct SceneChange {
    pub replacement: Replacement,
    /// Notices before the change (a cage flipped outward, a session's notes).
    pub notes: Vec<String>,
    /// The notice after it ("opened cage.obj").
    pub done: Option<String>,
    /// What File > Recent remembers.
    pub recent: Option<RecentEntry>,
    /// The session file it came from: File > Save session writes there.
    pub session: Option<PathBuf>,
    /// An edit of the scene shown (its cage subdivided, its mesh rested in the
    /// pose, a generated cage), which stays the session it was; anything opened
    /// is another scene, which Save session asks a name for.
    pub same_session: bool,
    /// Open the Generate cage window (a mesh with no cage of its own).
    pub offer_cage: bool,
}

impl SceneChange {
    fn new(replacement: Replacement) -> Self {
        Self {
            replacement,
            notes: Vec::new(),
            done: None,
            recent: None,
            session: None,
            same_session: false,
            offer_cage: false,
        }
    }

    /// An edit of the scene shown: the session stays.
    fn edit(mut self) -> Self {
        self.same_session = true;
        self
    }

    fn done(mut self, text: String) -> Self {
        self.done = Some(text);
        self
    }

    fn remembered(mut self, entry: RecentEntry) -> Self {
        self.recent = Some(entry);
        self
    }
}

/// A session: its mesh, cage, poses, method, parameters and views.
pub fn open_session(path: &Path) -> Result<SceneChange, String> {
    let opened = session::open_session(path).map_err(|error| error.to_string())?;
    let settings = opened.settings;
    let mut change = SceneChange::new(Replacement {
        document: opened.document,
        action: format!("open session {}", file_title(path)),
        cameras: Cameras::Session(settings.cameras),
        settings: Some((settings.bind_options, settings.view)),
    })
    .remembered(RecentEntry::Session(path.to_owned()))
    .done(format!("opened session {}", shown_path(path)));
    change.notes = opened.notes;
    change.session = Some(path.to_owned());
    Ok(change)
}

/// A mesh and its cage together, each the object of its file named in
/// `objects` (the file's default where none is).
pub fn open_pair(
    mesh_path: &Path,
    cage_path: &Path,
    objects: ObjectNames,
) -> Result<SceneChange, String> {
    let mut mesh = load_mesh_object(mesh_path, objects.mesh).map_err(|error| error.to_string())?;
    let (cage, report, cage_read) =
        load_cage_object(cage_path, objects.cage).map_err(|error| error.to_string())?;
    let mut notes = object_note(mesh_path, mesh.object_note.take());
    notes.extend(object_note(cage_path, cage_read.note));
    let document = Document::new(file_title(mesh_path), mesh.mesh.clone(), cage)
        .with_files(Some(mesh), Some(cage_path.to_owned()))
        .with_cage_objects(cage_read.objects);
    let action = format!(
        "open {} and {}",
        file_title(mesh_path),
        file_title(cage_path)
    );
    let mut change =
        SceneChange::new(Replacement::framed(document, action)).remembered(RecentEntry::Scene {
            mesh: mesh_path.to_owned(),
            cage: cage_path.to_owned(),
            mesh_object: objects.mesh.map(Into::into),
            cage_object: objects.cage.map(Into::into),
        });
    notes.extend(report.messages());
    change.notes = notes;
    Ok(change)
}

/// The mesh replaced (the cage kept) or the cage replaced (the mesh kept),
/// by object `object` of the file (its default where `None`). A mesh the
/// current cage holds none of sits in a loose box instead.
pub fn open_file(
    role: FileRole,
    path: &Path,
    object: Option<&str>,
    current: &Document,
) -> Result<SceneChange, String> {
    let (document, notes) = match role {
        FileRole::Mesh => {
            let mut file = load_mesh_object(path, object).map_err(|error| error.to_string())?;
            if !cage_reaches(current.cage(), &file.mesh) {
                return mesh_in_box(path, file, object);
            }
            let notes = object_note(path, file.object_note.take());
            let document = Document::new(
                file_title(path),
                file.mesh.clone(),
                (**current.cage()).clone(),
            )
            .with_files(Some(file), current.cage_path().map(Into::into))
            .with_cage_objects(current.cage_objects().clone());
            (document, notes)
        }
        FileRole::Cage => {
            let (cage, report, read) =
                load_cage_object(path, object).map_err(|error| error.to_string())?;
            let mut notes = object_note(path, read.note);
            notes.extend(report.messages());
            let rest = cage.positions().to_vec();
            let document = current
                .with_cage(cage, Some(path.to_owned()), rest)
                .with_cage_objects(read.objects);
            (document, notes)
        }
    };
    let role_name = match role {
        FileRole::Mesh => "mesh",
        FileRole::Cage => "cage",
    };
    let entry = recent_file(role, path, object);
    let action = format!("open {role_name} {}", file_title(path));
    let mut change = SceneChange::new(Replacement::framed(document, action))
        .remembered(entry)
        .done(format!("opened {}", shown_path(path)));
    change.notes = notes;
    Ok(change)
}

/// A mesh with no cage (`pmvc edit MESH`).
pub fn open_mesh_alone(path: &Path, object: Option<&str>) -> Result<SceneChange, String> {
    let file = load_mesh_object(path, object).map_err(|error| error.to_string())?;
    let mut change = mesh_in_box(path, file, object)?;
    change.recent = None;
    Ok(change)
}

/// `file`, read from `path` (its object `object` where one was named), in a
/// loose box cage, with the Generate cage window offering a real one.
fn mesh_in_box(
    path: &Path,
    mut file: MeshFile,
    object: Option<&str>,
) -> Result<SceneChange, String> {
    let notes = object_note(path, file.object_note.take());
    let cage = loose_box_cage(&file.mesh).ok_or_else(|| {
        format!(
            "{}: the mesh has no extent to put a cage around",
            shown_path(path)
        )
    })?;
    let title = file_title(path);
    let document =
        Document::new(title.clone(), file.mesh.clone(), cage).with_files(Some(file), None);
    let mut change = SceneChange::new(Replacement::framed(document, format!("open {title}")))
        .remembered(recent_file(FileRole::Mesh, path, object))
        .done(format!(
            "opened {} in a box cage; generate a cage for it (File > Generate cage…)",
            shown_path(path)
        ));
    change.offer_cage = true;
    change.notes = notes;
    Ok(change)
}

/// A bundled scene.
pub fn open_bundled(bundled: BundledScene) -> Result<SceneChange, String> {
    let (mesh, cage) = bundled.build().map_err(|error| error.to_string())?;
    let action = format!("open the {} scene", bundled.title());
    let document = Document::new(bundled.title(), mesh, cage).bundled_as(bundled);
    Ok(SceneChange::new(Replacement::framed(document, action)))
}

/// The cage subdivided 1-to-4 at edge midpoints, keeping the current pose
/// (smoother coordinates near reflex edges, the paper's Figure 4).
pub fn subdivide_cage(current: &Document) -> Result<SceneChange, String> {
    let subdivided = subdivide_midpoint(current.cage(), current.pose())
        .map_err(|error| format!("cannot subdivide the cage: {error}"))?;
    let before = current.pose().len();
    let after = subdivided.cage.vertex_count();
    let document = current.with_cage(
        subdivided.cage,
        current.cage_path().map(Into::into),
        subdivided.pose,
    );
    Ok(
        SceneChange::new(Replacement::in_place(document, "subdivide the cage"))
            .edit()
            .done(format!(
                "subdivided the cage: {before} -> {after} vertices; rebinding"
            )),
    )
}

/// The current pose as the rest shape: the mesh takes the shape `method` gives
/// it, and the cage rests in its pose.
pub fn pose_as_rest(current: &Document, method: Method) -> Result<SceneChange, String> {
    if current.bound(method).is_none() {
        return Err(format!(
            "cannot use the pose as rest shape before {method} is bound: the mesh would not follow the cage"
        ));
    }
    let mesh = TriMesh {
        positions: current.deformed_positions(method),
        ..(**current.mesh()).clone()
    };
    let cage = current.cage().with_positions(current.pose().to_vec());
    let document = Document::new(current.title(), mesh, cage).with_files(
        current.mesh_file().cloned(),
        current.cage_path().map(Into::into),
    );
    Ok(
        SceneChange::new(Replacement::in_place(document, "use pose as rest shape"))
            .edit()
            .done(format!(
                "the mesh now rests as {method} deformed it, in the posed cage; rebinding"
            )),
    )
}

/// The generated cage of `proposal` as the document's cage.
pub fn use_generated_cage(current: &Document, proposal: Proposal) -> SceneChange {
    let cage = proposal.generated.cage;
    let vertices = cage.vertex_count();
    let rest = cage.positions().to_vec();
    let document = current.with_cage(cage, None, rest);
    SceneChange::new(Replacement::framed(
        document,
        format!("use the generated {vertices}-vertex cage"),
    ))
    .edit()
    .done(format!(
        "using the generated cage of {vertices} vertices; binding"
    ))
}

/// A pose file's positions: a cage-shaped OBJ/OFF with one vertex per cage vertex.
pub fn read_pose(path: &Path, current: &Document) -> Result<Vec<DVec3>, String> {
    let file = crate::formats::load_mesh(path).map_err(|error| error.to_string())?;
    check_pose(path, file.mesh.positions, current)
}

/// `positions`, read from `path`, when they are one per cage vertex and within
/// the reach a session may hold, so that what is saved can be opened again.
pub fn check_pose(
    path: &Path,
    positions: Vec<DVec3>,
    current: &Document,
) -> Result<Vec<DVec3>, String> {
    let cage_vertices = current.pose().len();
    if positions.len() != cage_vertices {
        return Err(format!(
            "{}: the pose has {} vertices but the cage has {cage_vertices}",
            shown_path(path),
            positions.len(),
        ));
    }
    let reach = super::session_checks::Reach::of(current.cage().positions());
    if let Some((number, distance)) = reach.first_beyond(&positions) {
        let problem = reach.describe(number, distance);
        return Err(format!("{}: {problem}", shown_path(path)));
    }
    Ok(positions)
}

/// An error when `path` is (or links to) the open mesh or cage: saving a pose
/// over the rest cage, or a deformed mesh over its source, would lose the
/// scene's input.
pub fn refuse_overwriting_open_files(path: &Path, current: &Document) -> Result<(), String> {
    refuse_overwriting_inputs(path, current, None)
}

/// The files the open scene was read from: its mesh, its cage and the session
/// that named them. Only Save session may write the session file.
pub fn open_inputs<'a>(current: &'a Document, session: Option<&'a Path>) -> Vec<&'a Path> {
    let mut inputs = Vec::new();
    inputs.extend(current.mesh_file().map(|file| file.path.as_path()));
    inputs.extend(current.cage_path());
    inputs.extend(session);
    inputs
}

/// [`refuse_overwriting_open_files`], the session file included.
pub fn refuse_overwriting_inputs(
    path: &Path,
    current: &Document,
    session: Option<&Path>,
) -> Result<(), String> {
    refuse_same_file(path, &open_inputs(current, session)).map_err(|error| error.to_string())
}

/// Write the pose as an OBJ with the cage's faces as read (quads stay quads),
/// as `pmvc deform` reads poses and Save cage writes them.
pub fn save_pose(path: &Path, current: &Document) -> Result<String, String> {
    refuse_overwriting_open_files(path, current)?;
    let cage = current.cage();
    let posed = TriMesh {
        positions: current.pose().to_vec(),
        triangles: cage.triangles().to_vec(),
        triangle_faces: cage.triangle_faces().to_vec(),
    };
    let faces = polygons_of(&posed);
    write_atomically(path, |out| {
        write_polygons_obj_to(out, &posed.positions, &faces)
    })
    .map_err(|error| error.to_string())?;
    Ok(format!("saved pose {}", shown_path(path)))
}

/// Where Save cage puts the pose beside the rest cage at `path`:
/// `hand_cage.obj` → `hand_cage.posed.obj`.
pub fn posed_cage_path(path: &Path) -> PathBuf {
    let stem = path
        .file_stem()
        .map_or_else(|| "cage".into(), |s| s.to_string_lossy().into_owned());
    path.with_file_name(format!("{stem}.posed.obj"))
}

/// Write the rest cage to `path`, its polygons as read (quads stay quads), and
/// the current pose beside it ([`posed_cage_path`]); both or neither.
pub fn save_cage(path: &Path, current: &Document) -> Result<String, String> {
    let posed = posed_cage_path(path);
    refuse_overwriting_open_files(path, current)?;
    refuse_overwriting_open_files(&posed, current)?;
    let cage = current.cage();
    let rest = TriMesh {
        positions: cage.positions().to_vec(),
        triangles: cage.triangles().to_vec(),
        triangle_faces: cage.triangle_faces().to_vec(),
    };
    write_cage_and_pose(path, &posed, &rest, current.pose()).map_err(|e| e.to_string())?;
    Ok(format!(
        "saved the cage {} and its pose {}",
        shown_path(path),
        shown_path(&posed)
    ))
}

/// Write the session: the document and `settings`.
pub fn save_session(
    path: &Path,
    current: &Document,
    settings: &SessionSettings,
) -> Result<String, String> {
    refuse_overwriting_open_files(path, current)?;
    session::save_session(path, current, settings).map_err(|error| error.to_string())?;
    Ok(format!("saved session {}", shown_path(path)))
}

/// The base shape of a glTF export (Blender's Basis shape key).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GltfBase {
    /// The mesh as read: an import lands where the original was.
    Rest,
    /// The mesh deformed with the current pose (File > Export glTF, pose as base).
    Pose,
}

/// Write the mesh deformed with `method` as glTF: `base` as the base shape,
/// each named pose as a morph target named after it, and the timeline's keys,
/// when it has two or more, as the animation, which starts at the base (a key
/// at 0 s with every weight 0) unless a pose is keyed at 0 s.
pub fn export_gltf(
    path: &Path,
    current: &Document,
    method: Method,
    base_shape: GltfBase,
) -> Result<String, String> {
    use crate::formats::gltf::{write_gltf, AnimationKey, GltfPose, GltfScene};
    refuse_overwriting_open_files(path, current)?;
    if current.weights(method).is_none() {
        return Err(format!(
            "{}: not exported: {} is not bound yet",
            shown_path(path),
            method.name()
        ));
    }
    let base = match base_shape {
        GltfBase::Rest => current.mesh().positions.clone(),
        GltfBase::Pose => current.deformed_positions(method),
    };
    let named = current.named_poses();
    let deformed: Vec<Vec<DVec3>> = named
        .iter()
        .map(|pose| current.deformed_positions_at(method, &pose.positions))
        .collect();
    let poses: Vec<GltfPose> = named
        .iter()
        .zip(&deformed)
        .map(|(pose, positions)| GltfPose {
            name: &pose.name,
            positions,
        })
        .collect();
    let timeline = crate::app::timeline::keys(named);
    let mut keys: Vec<AnimationKey> = Vec::with_capacity(timeline.len() + 1);
    if timeline.first().is_some_and(|&(seconds, _)| seconds > 0.0) {
        keys.push(AnimationKey {
            seconds: 0.0,
            pose: None,
        });
    }
    keys.extend(timeline.iter().map(|&(seconds, index)| AnimationKey {
        seconds: seconds as f32,
        pose: Some(index),
    }));
    let animated = timeline.len() >= 2;
    let made;
    let mesh = match current.mesh_file() {
        Some(file) => file,
        None => {
            made = MeshFile {
                path: PathBuf::from(current.title()),
                format: crate::formats::MeshFormat::Obj,
                mesh: (**current.mesh()).clone(),
                obj_text: None,
                node_transform: None,
                object_note: None,
                objects: Default::default(),
            };
            &made
        }
    };
    let scene = GltfScene {
        mesh,
        base: &base,
        poses: &poses,
        animation: animated.then_some(keys.as_slice()),
    };
    write_gltf(path, &scene).map_err(|error| error.to_string())?;
    let animated = if animated {
        format!(", an animation of {} keys", keys.len())
    } else {
        String::new()
    };
    let base_shape = match base_shape {
        GltfBase::Rest => "the rest mesh",
        GltfBase::Pose => "the current pose",
    };
    Ok(format!(
        "exported {} ({}, {base_shape} as its base, {} morph target(s){animated})",
        shown_path(path),
        method.name(),
        poses.len()
    ))
}

/// Write the mesh deformed with `method`.
pub fn export_deformed(path: &Path, current: &Document, method: Method) -> Result<String, String> {
    refuse_overwriting_open_files(path, current)?;
    let positions = current.deformed_positions(method);
    let moved = match current.mesh_file() {
        Some(file) => write_deformed_mesh(file, &positions, path),
        None => write_mesh_with_normals(path, &positions, &current.mesh().triangles)
            .map(|()| Vec::new()),
    }
    .map_err(|error| error.to_string())?;
    let mut done = format!("exported {}", shown_path(path));
    for library in moved {
        done.push_str(&format!("; {library}"));
    }
    Ok(done)
}

/// The name a new session file is offered: the mesh's, as
/// "hydrant.session.json" for hydrant.obj.
pub fn session_name(document: &Document) -> String {
    let title = match document.mesh_file() {
        Some(file) => file
            .path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned()),
        None => Path::new(document.title())
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned()),
    };
    let stem = title
        .filter(|t| !t.trim().is_empty())
        .unwrap_or_else(|| "scene".into());
    format!("{stem}.session.json")
}

/// The name a saved cage is offered: the cage file's with "-edited" (the
/// file itself is an input, never overwritten), or the mesh's with "_cage"
/// for a cage that came from no file (generated, a box, bundled).
pub fn cage_name(document: &Document) -> String {
    let stem = |path: &Path| path.file_stem().map(|s| s.to_string_lossy().into_owned());
    match document.cage_path().and_then(stem) {
        Some(cage) => format!("{cage}-edited.obj"),
        None => {
            let mesh = session_name(document);
            format!("{}_cage.obj", mesh.trim_end_matches(".session.json"))
        }
    }
}
