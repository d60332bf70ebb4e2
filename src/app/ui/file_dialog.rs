//! File dialogs that always appear. The system's dialog (rfd, through the desktop
//! portal) is used where it works. Where it cannot appear (a bare X session, many
//! window managers, WSL, containers: no portal answers), or when the user asks for
//! it in the File menu, a dialog inside the window takes its place: it browses
//! folders, lists meshes, and takes a typed path for every file action.

use crate::app::actions::Action;
pub use crate::app::actions::FileAction;
use crate::app::ctx::PanelContext;
use crate::formats::shown_path;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// A system dialog that comes back empty sooner than this was never shown: no
/// person cancels a dialog that fast.
const SYSTEM_DIALOG_MIN_TIME: Duration = Duration::from_millis(250);

// What the dialogs show and list for each action.
impl FileAction {
    pub fn title(self) -> &'static str {
        match self {
            FileAction::OpenMesh => "Open mesh",
            FileAction::OpenCage => "Open cage",
            FileAction::LoadPose => "Load pose",
            FileAction::SavePose => "Save pose",
            FileAction::SaveCage => "Save cage",
            FileAction::ExportMesh => "Export deformed mesh",
            FileAction::OpenSession => "Open session",
            FileAction::SaveSession => "Save session",
            FileAction::SaveImage => "Save image",
            FileAction::ExportColouredMesh => "Export coloured mesh",
            FileAction::ExportGltf => "Export glTF",
            FileAction::ExportGltfPosedBase => "Export glTF, the pose as its base",
        }
    }

    fn saves(self) -> bool {
        matches!(
            self,
            FileAction::SavePose
                | FileAction::SaveCage
                | FileAction::ExportMesh
                | FileAction::SaveSession
                | FileAction::SaveImage
                | FileAction::ExportColouredMesh
                | FileAction::ExportGltf
                | FileAction::ExportGltfPosedBase
        )
    }

    /// The extensions of the files this action lists; a saved file without
    /// one gets the first.
    fn extensions(self) -> &'static [&'static str] {
        match self {
            FileAction::OpenSession | FileAction::SaveSession => &["json"],
            FileAction::SaveImage => &["png"],
            FileAction::ExportColouredMesh => &["ply"],
            FileAction::ExportGltf | FileAction::ExportGltfPosedBase => &["glb", "gltf"],
            // Point sets (n × 3 arrays) open wherever a mesh does, and glTF's
            // first mesh.
            FileAction::OpenMesh => &["obj", "off", "npy", "glb", "gltf"],
            FileAction::LoadPose => &["obj", "off", "npy"],
            _ => &["obj", "off"],
        }
    }

    fn extension(self) -> &'static str {
        self.extensions()[0]
    }

    /// Files the dialog lists for this action.
    fn lists(self, name: &str) -> bool {
        let lower = name.to_lowercase();
        self.extensions()
            .iter()
            .any(|extension| lower.ends_with(&format!(".{extension}")))
    }

    fn default_name(self) -> &'static str {
        match self {
            FileAction::SavePose => "pose.obj",
            FileAction::SaveCage => "cage.obj",
            FileAction::ExportMesh => "deformed.obj",
            FileAction::SaveSession => "scene.session.json",
            FileAction::SaveImage => "view.png",
            FileAction::ExportColouredMesh => "coloured.ply",
            FileAction::ExportGltf | FileAction::ExportGltfPosedBase => "deformed.glb",
            _ => "",
        }
    }

    fn confirm_label(self) -> &'static str {
        match self {
            FileAction::OpenMesh | FileAction::OpenCage | FileAction::OpenSession => "Open",
            FileAction::LoadPose => "Load",
            FileAction::SavePose
            | FileAction::SaveCage
            | FileAction::SaveSession
            | FileAction::SaveImage => "Save",
            FileAction::ExportMesh
            | FileAction::ExportColouredMesh
            | FileAction::ExportGltf
            | FileAction::ExportGltfPosedBase => "Export",
        }
    }
}

/// One line of the in-window dialog's listing.
struct Entry {
    name: String,
    is_folder: bool,
}

/// The in-window dialog while it is open.
struct FileBrowser {
    action: FileAction,
    folder: PathBuf,
    folder_text: String,
    entries: Vec<Entry>,
    name: String,
    problem: Option<String>,
    /// A save over this existing file was asked for once; a second Save replaces it.
    confirm_replace: Option<PathBuf>,
    /// The name field takes the keyboard when the dialog opens, so a typed name
    /// and Enter work at once.
    focus_name: bool,
    /// The name offered when the dialog opened, offered again in each folder.
    suggested: String,
}

impl FileBrowser {
    fn new(action: FileAction, folder: PathBuf, name: String) -> Self {
        let mut browser = Self {
            action,
            folder: PathBuf::new(),
            folder_text: String::new(),
            entries: Vec::new(),
            name: name.clone(),
            suggested: name,
            problem: None,
            confirm_replace: None,
            focus_name: true,
        };
        browser.enter(folder);
        browser
    }

    /// List `folder`: its folders, then its OBJ and OFF files, by name. A folder
    /// that cannot be read leaves the listing as it was and says why.
    fn enter(&mut self, folder: PathBuf) {
        let read = match std::fs::read_dir(&folder) {
            Ok(read) => read,
            Err(error) => {
                self.problem = Some(format!("cannot open {}: {error}", shown_path(&folder)));
                self.folder_text = self.folder.display().to_string();
                return;
            }
        };
        let action = self.action;
        let mut entries: Vec<Entry> = read
            .flatten()
            .filter_map(|item| {
                let name = item.file_name().to_string_lossy().into_owned();
                // Follows links, so a linked folder opens like a folder.
                let is_folder = item.path().is_dir();
                let listed = !name.starts_with('.') && (is_folder || action.lists(&name));
                listed.then_some(Entry { name, is_folder })
            })
            .collect();
        entries.sort_by_key(|entry| (!entry.is_folder, entry.name.to_lowercase()));
        self.entries = entries;
        self.folder_text = folder.display().to_string();
        self.folder = folder;
        self.problem = None;
        self.confirm_replace = None;
    }

    /// The path the file name field names: absolute, or in the shown folder.
    fn chosen_path(&self) -> PathBuf {
        let typed = expand_home(self.name.trim());
        let path = self.folder.join(typed);
        if self.action.saves() && path.extension().is_none() {
            path.with_extension(self.action.extension())
        } else {
            path
        }
    }
}

/// Select the name up to its first dot, as system dialogs do, so typing
/// replaces "scene" in "scene.session.json" and keeps the extension.
fn select_stem(ctx: &egui::Context, id: egui::Id, name: &str) {
    use egui::text::{CCursor, CCursorRange};
    let stem = name.find('.').unwrap_or(name.len());
    let chars = name[..stem].chars().count();
    let mut state = egui::TextEdit::load_state(ctx, id).unwrap_or_default();
    state.cursor.set_char_range(Some(CCursorRange::two(
        CCursor::new(0),
        CCursor::new(chars),
    )));
    state.store(ctx, id);
}

/// `~/x` as the shell reads it.
fn expand_home(text: &str) -> PathBuf {
    match (text.strip_prefix("~/"), std::env::var_os("HOME")) {
        (Some(rest), Some(home)) => Path::new(&home).join(rest),
        _ => PathBuf::from(text),
    }
}

/// Which dialog file actions use, and the in-window one while it is open.
pub struct FileDialogs {
    /// Use the in-window dialog (the File menu's switch, or the system's failed).
    pub in_window: bool,
    browser: Option<FileBrowser>,
    /// Where the next in-window dialog starts: the folder last used.
    folder: Option<PathBuf>,
}

impl Default for FileDialogs {
    /// The system's dialog where a desktop session bus can carry the portal's
    /// request; the in-window one where there is none to ask.
    fn default() -> Self {
        let no_portal = cfg!(target_os = "linux")
            && std::env::var_os("DBUS_SESSION_BUS_ADDRESS").is_none_or(|v| v.is_empty());
        Self {
            in_window: no_portal,
            browser: None,
            folder: None,
        }
    }
}

impl FileDialogs {
    /// The in-window dialog is open (it takes the keyboard from the viewport).
    pub fn is_open(&self) -> bool {
        self.browser.is_some()
    }

    fn start_folder(&self) -> PathBuf {
        self.folder
            .clone()
            .or_else(|| std::env::current_dir().ok())
            .unwrap_or_else(|| PathBuf::from("/"))
    }
}

/// What asking for a file gave at once.
pub enum DialogAnswer {
    /// The system's dialog gave this file.
    Chosen(PathBuf),
    /// The system's dialog was cancelled.
    Cancelled,
    /// The in-window dialog opened, and answers in a later frame; `fell_back`
    /// when the system's dialog did not appear.
    InWindow { fell_back: bool },
}

impl FileDialogs {
    /// Ask for a file for `action`, offering `name` (else the action's usual
    /// name) where a file is saved: the system's dialog when it works, else the
    /// in-window one.
    pub fn ask(&mut self, action: FileAction, name: Option<String>) -> DialogAnswer {
        let name = name.unwrap_or_else(|| action.default_name().into());
        let mut fell_back = false;
        if !self.in_window {
            let asked = Instant::now();
            match system_dialog(action, &self.start_folder(), &name) {
                Some(path) => return DialogAnswer::Chosen(path),
                None if asked.elapsed() >= SYSTEM_DIALOG_MIN_TIME => {
                    return DialogAnswer::Cancelled;
                }
                None => {
                    self.in_window = true;
                    fell_back = true;
                }
            }
        }
        let folder = self.start_folder();
        self.browser = Some(FileBrowser::new(action, folder, name));
        DialogAnswer::InWindow { fell_back }
    }

    /// The action the in-window dialog is open for, if it is.
    pub fn open_for(&self) -> Option<FileAction> {
        self.browser.as_ref().map(|b| b.action)
    }

    /// The file name the in-window dialog holds, if it is open.
    pub fn typed_name(&self) -> Option<&str> {
        self.browser.as_ref().map(|b| b.name.as_str())
    }

    /// The next in-window dialog starts in the folder of `path`.
    pub fn remember_folder(&mut self, path: &Path) {
        if let Some(folder) = path.parent().filter(|f| f.is_dir()) {
            self.folder = Some(folder.to_owned());
        }
    }

    /// The in-window dialog's file was carried out (`failed` is `None`) and the
    /// dialog closes, or it failed and the dialog stays, saying why, so that
    /// another file can be chosen.
    pub fn answered(&mut self, failed: Option<String>) {
        match (failed, self.browser.as_mut()) {
            (None, _) => self.browser = None,
            (Some(problem), Some(browser)) => {
                browser.problem = Some(problem);
                browser.confirm_replace = None;
            }
            (Some(_), None) => {}
        }
    }

    /// The in-window dialog, while it is open: it sends the chosen file, or the
    /// cancel.
    pub fn window(&mut self, ctx: &egui::Context, cx: &mut PanelContext) {
        let Some(browser) = self.browser.as_mut() else {
            return;
        };
        let action = browser.action;
        let mut confirm = false;
        let mut cancel = ctx.input(|i| i.key_pressed(egui::Key::Escape));
        egui::Window::new(format!("{} (in-window dialog)", action.title()))
            .collapsible(false)
            .resizable(false)
            .anchor(egui::Align2::CENTER_CENTER, egui::Vec2::ZERO)
            .default_width(520.0)
            .show(ctx, |ui| {
                ui.weak(
                    "pmvc's own dialog; File > In-window file dialog switches back to the system's",
                );
                ui.horizontal(|ui| {
                    let label = ui.label("Folder:");
                    if ui.button("Up").clicked() {
                        if let Some(parent) = browser.folder.parent().map(Path::to_owned) {
                            browser.enter(parent);
                        }
                    }
                    let field = ui
                        .add(
                            egui::TextEdit::singleline(&mut browser.folder_text)
                                .desired_width(380.0),
                        )
                        .labelled_by(label.id);
                    if field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter)) {
                        let typed = expand_home(browser.folder_text.trim());
                        browser.enter(typed);
                    }
                });
                let mut enter = None;
                egui::ScrollArea::vertical()
                    .max_height(260.0)
                    .auto_shrink([false, false])
                    .show(ui, |ui| {
                        if browser.entries.is_empty() {
                            ui.weak(format!(
                                "(no folders or {} files here)",
                                browser.action.extensions().join(" or ").to_uppercase()
                            ));
                        }
                        for entry in &browser.entries {
                            if entry.is_folder {
                                if ui
                                    .selectable_label(false, format!("{}/", entry.name))
                                    .clicked()
                                {
                                    enter = Some(browser.folder.join(&entry.name));
                                }
                            } else {
                                let chosen = browser.name == entry.name;
                                let row = ui.selectable_label(chosen, &entry.name);
                                if row.clicked() {
                                    browser.name = entry.name.clone();
                                    browser.confirm_replace = None;
                                }
                                confirm |= row.double_clicked();
                            }
                        }
                    });
                if let Some(folder) = enter {
                    browser.enter(folder);
                }
                ui.horizontal(|ui| {
                    let label = ui.label("File name:");
                    let field = ui
                        .add(egui::TextEdit::singleline(&mut browser.name).desired_width(380.0))
                        .labelled_by(label.id);
                    if std::mem::take(&mut browser.focus_name) {
                        field.request_focus();
                        select_stem(ui.ctx(), field.id, &browser.name);
                    }
                    if field.changed() {
                        browser.confirm_replace = None;
                    }
                    confirm |= field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
                });
                if let Some(problem) = &browser.problem {
                    ui.colored_label(ui.visuals().error_fg_color, problem);
                }
                ui.horizontal(|ui| {
                    confirm |= ui.button(action.confirm_label()).clicked();
                    cancel |= ui.button("Cancel").clicked();
                });
            });
        if cancel {
            self.browser = None;
            cx.send(Action::FileCancelled(action));
        } else if confirm {
            self.confirm_in_window_dialog(cx);
        }
    }

    /// The in-window dialog's confirm: a folder opens, a missing file or an
    /// unconfirmed replacement is said in the dialog, anything else is carried out.
    fn confirm_in_window_dialog(&mut self, cx: &mut PanelContext) {
        let Some(browser) = self.browser.as_mut() else {
            return;
        };
        let action = browser.action;
        let path = browser.chosen_path();
        if browser.name.trim().is_empty() {
            browser.problem = Some("type a file name or pick a file".into());
            return;
        }
        if path.is_dir() {
            browser.enter(path);
            browser.name = browser.suggested.clone();
            return;
        }
        if !action.saves() && !path.is_file() {
            browser.problem = Some(format!("{} does not exist", shown_path(&path)));
            return;
        }
        if action.saves() && path.exists() && browser.confirm_replace.as_ref() != Some(&path) {
            browser.problem = Some(format!(
                "{} exists: {} again to replace it",
                shown_path(&path),
                action.confirm_label()
            ));
            browser.confirm_replace = Some(path);
            return;
        }
        // The dialog stays open until the editor says how the file fared.
        cx.send(Action::FileChosen(action, path));
    }
}

/// The system's file dialog for `action`; None when cancelled or not shown.
fn system_dialog(action: FileAction, folder: &Path, name: &str) -> Option<PathBuf> {
    let dialog = rfd::FileDialog::new()
        .set_title(action.title())
        .set_directory(folder);
    let extensions = action.extensions();
    let kind = extensions.join("/").to_uppercase();
    if action.saves() {
        dialog
            .set_file_name(name)
            .add_filter(&kind, &extensions[..1])
            .save_file()
    } else {
        let mut both_cases: Vec<String> = extensions.iter().map(|e| e.to_string()).collect();
        both_cases.extend(extensions.iter().map(|e| e.to_uppercase()));
        dialog.add_filter(&kind, &both_cases).pick_file()
    }
}
