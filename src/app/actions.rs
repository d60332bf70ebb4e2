//! What panels and shortcuts ask the editor to do, as values (egui's demo app
//! returns its commands the same way), and the small types an action carries:
//! which file, which side to look from, the dialogs' answers. The editor's one
//! runner (`editor/runner.rs`) carries them out: actions do the I/O, and what
//! changes the document goes on to the model as a [`Command`]. A leaf: it
//! imports nothing of the editor or the panels, so both can depend on it.

use super::commands::Command;
use super::compare::ViewSettings;
use super::recent::RecentEntry;
use super::scenes::BundledScene;
use crate::coords::{Method, Parameter};
use glam::DVec3;
use std::path::PathBuf;

/// Something a panel or a shortcut asks for.
#[derive(Debug)]
pub enum Action {
    /// File > Quit, Ctrl+Q: close now when nothing would be lost, else ask.
    Quit,
    /// Close the window: the user confirmed quitting.
    CloseWindow,
    /// The answer to "Save changes before quitting (or opening)?".
    Unsaved(UnsavedAnswer),
    /// The answer about a recovery file left by an editor that did not exit.
    Recover(PathBuf, RecoverAnswer),
    /// Open the file dialog for `FileAction`.
    AskForFile(FileAction),
    /// The in-window dialog's answer: carry out `FileAction` on the path.
    FileChosen(FileAction, PathBuf),
    /// A file dialog was closed without a file.
    FileCancelled(FileAction),
    /// Open a file as the mesh or the cage.
    Open(FileRole, PathBuf),
    /// Read another object of the mesh's or the cage's file in its place
    /// (`None`: the file's default, an OBJ's objects together or a glTF's
    /// first mesh).
    OpenObject {
        role: FileRole,
        object: Option<String>,
    },
    /// Open a mesh and its cage together.
    OpenPair {
        mesh: PathBuf,
        cage: PathBuf,
    },
    /// Open a File > Recent entry; one that no longer opens leaves the list.
    OpenRecent(RecentEntry),
    /// Open a bundled scene.
    OpenBundled(BundledScene),
    /// Open a session file (one dropped on the window).
    OpenSession(PathBuf),
    /// Use the vertices read from `path` as the cage's pose.
    TakePose {
        path: PathBuf,
        pose: Vec<DVec3>,
    },
    /// File > Save session: where it was last saved or opened, else ask.
    SaveSessionAgain,
    /// Report an error to the user.
    Error(String),
    /// Tell the user something.
    Info(String),
    /// Remove the notice at this index of the list.
    DismissNotice(usize),
    /// Change the model.
    Apply(Command),
    Undo,
    Redo,
    /// Pose the cage at rest, as one undo step.
    ResetPose,
    /// Edit > Use pose as rest shape.
    PoseAsRest,
    /// Subdivide the cage 1-to-4, keeping the pose, and bind again.
    SubdivideCage,
    /// Move one handle to a typed position, as one undo step.
    SetHandlePosition(usize, DVec3),
    /// The rest-to-pose blend slider.
    Blend(BlendStep),
    /// Keep the current pose under a name.
    StoreNamedPose(String),
    /// Pose the cage as the named pose at this index.
    ApplyNamedPose(usize),
    RenameNamedPose {
        index: usize,
        name: String,
    },
    /// Show these view settings.
    SetView(ViewSettings),
    /// The family a single view shows.
    SetMethod(Method),
    /// The next family (the M key).
    NextMethod,
    /// A family parameter, checked by its spec.
    SetParameter(Parameter, u32),
    /// One family's parameter, shown or not (the side panel's controls).
    SetFamilyParameter(Method, u32),
    /// A setting read when weights deform a pose (Somigliana's bulging),
    /// checked by its spec; an undo step, and nothing is bound again.
    SetDeformParameter(Parameter, u32),
    /// Bind quads as bilinear patches, or split along a diagonal (`--triangulate`).
    SetQuadSplit(crate::coords::QuadSplit),
    /// Bind the methods the views show, replacing a running bind.
    StartBind,
    /// Cancel the running bind; views stop asking until the user binds again.
    CancelBind,
    SetHighlightOutside(bool),
    /// Anti-aliasing: the viewport's samples per pixel.
    SetSampleCount(u32),
    /// One camera for every view, or one each.
    SetCamerasLocked(bool),
    /// Keep the difference's colour scale at the distance shown now, or go back
    /// to following the largest distance.
    FixDifferenceScale(bool),
    FrameSelection,
    FrameAll,
    /// Show or hide the cage and its handles (H).
    ToggleCage,
    /// Soft selection on or off (O).
    ToggleSoftSelection,
    ShowStatistics(bool),
    /// pmvc's own file dialog instead of the system's.
    SetInWindowDialog(bool),
    /// The Generate cage window.
    CageWindow(CageRequest),
    /// Hide the first run's line.
    HideFirstRunLine,
    /// Help > Shortcuts.
    ShowShortcuts,
    /// Select every handle (A).
    SelectAll,
    /// Select the handles not selected, and only those (Ctrl+I).
    InvertSelection,
    /// Every view looks at the scene from this side.
    ViewFrom(ViewSide),
    /// Every view switches between parallel and perspective (numpad 5).
    ToggleOrthographic,
}

/// A step of the blend slider's gesture.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BlendStep {
    /// The slider's drag began.
    Begin,
    /// Show the blend at this amount (0 to 1) while the drag lasts.
    Preview(f64),
    /// The drag ended: one undo step.
    End,
    /// A click or a typed amount: the blend at once, as one undo step.
    Set(f64),
}

/// What the Generate cage window asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CageRequest {
    Open,
    Close,
    Generate,
    /// Cancel the job, or discard the proposal.
    Cancel,
    /// Use the proposal as the cage.
    Use,
}

/// Which kind of file is being opened.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileRole {
    Mesh,
    Cage,
}

/// What a file dialog is asked for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileAction {
    OpenMesh,
    OpenCage,
    LoadPose,
    SavePose,
    /// The rest cage, polygons kept, and its pose beside it.
    SaveCage,
    ExportMesh,
    OpenSession,
    SaveSession,
    SaveImage,
    ExportColouredMesh,
    /// The deformed mesh as glTF, named poses as morph targets, the timeline
    /// as its animation; the rest mesh as its base shape.
    ExportGltf,
    /// [`FileAction::ExportGltf`] with the current pose as its base shape.
    ExportGltfPosedBase,
}

/// A side to look at the scene from, as Blender's numpad views: the scene's y
/// axis is up, and the front looks along −z.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ViewSide {
    Front,
    Back,
    Right,
    Left,
    Top,
    Bottom,
}

impl ViewSide {
    /// The camera's yaw and pitch (radians) for this side.
    pub fn yaw_pitch(self) -> (f32, f32) {
        use std::f32::consts::{FRAC_PI_2, PI};
        match self {
            ViewSide::Front => (0.0, 0.0),
            ViewSide::Back => (PI, 0.0),
            ViewSide::Right => (FRAC_PI_2, 0.0),
            ViewSide::Left => (-FRAC_PI_2, 0.0),
            ViewSide::Top => (0.0, FRAC_PI_2),
            ViewSide::Bottom => (0.0, -FRAC_PI_2),
        }
    }
}

/// The user's answer to "Save changes before quitting (or opening)?".
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UnsavedAnswer {
    /// Save the session (where it came from, else ask a name), then go on.
    SaveSession,
    /// Save the pose as OBJ, then go on: offered when only the pose is unsaved.
    SavePose,
    /// Go on without saving.
    Discard,
    /// Neither save nor go on.
    Cancel,
}

/// The user's answer about a recovery file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RecoverAnswer {
    /// Open it as unsaved work.
    Restore,
    /// Delete it.
    Discard,
    /// Keep it for the next start.
    Later,
}
