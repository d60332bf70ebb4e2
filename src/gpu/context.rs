//! The device a bind runs on: chosen here by the adapter policy, or handed in by the
//! editor so that the weights stay in its GPU memory.

use super::kernels::Kernels;
use super::pipeline_cache::{self, CacheLoad};
use super::GpuError;
use std::fmt::Write as _;
use std::sync::{Arc, Mutex, OnceLock};
use std::time::{Duration, Instant};

/// A wgpu device and queue with the facts a bind needs about them.
pub struct GpuContext {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: wgpu::AdapterInfo,
    pub limits: wgpu::Limits,
    /// Set by the device-lost callback and by uncaptured errors on devices made here.
    failure: Arc<Mutex<Option<GpuError>>>,
    kernels: OnceLock<Result<Kernels, GpuError>>,
    /// The pipeline cache found on disk when the device opened; `Unsupported`
    /// where the device was opened without the feature (the editor's).
    pipeline_cache: CacheLoad,
    /// From listing the adapters to the device ready; zero for a device handed in.
    opened_in: Duration,
    /// Lines for the user about the pipeline cache (ignored or unwritable files).
    notices: Mutex<Vec<String>>,
}

impl std::fmt::Debug for GpuContext {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GpuContext")
            .field("adapter", &self.info.name)
            .field("backend", &self.info.backend)
            .finish_non_exhaustive()
    }
}

impl GpuContext {
    /// Open a device by the adapter policy of [`choose_adapter`]: `WGPU_BACKEND`
    /// limits the backends, `WGPU_ADAPTER_NAME` picks by name, otherwise the best
    /// hardware adapter, and a software one (`DeviceType::Cpu`) only when there is none.
    pub fn new() -> Result<Self, GpuError> {
        let started = Instant::now();
        let instance = make_instance();
        let adapters = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::all()));
        Self::open(choose_adapter(adapters)?, started)
    }

    /// [`GpuContext::new`], or `None` when the adapter it would choose is a software
    /// one, found without opening a device on it. Where the system has no GPU device
    /// at all ([`may_have_hardware_adapter`]) it answers `None` without listing the
    /// adapters, which loads every installed driver (60–90 ms with Mesa's).
    pub fn new_hardware() -> Result<Option<Self>, GpuError> {
        if !may_have_hardware_adapter(std::path::Path::new("/dev")) {
            return Ok(None);
        }
        let started = Instant::now();
        let instance = make_instance();
        let adapters = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::all()));
        let adapter = choose_adapter(adapters)?;
        if adapter.get_info().device_type == wgpu::DeviceType::Cpu {
            return Ok(None);
        }
        Self::open(adapter, started).map(Some)
    }

    fn open(adapter: wgpu::Adapter, started: Instant) -> Result<Self, GpuError> {
        let info = adapter.get_info();
        let wanted = adapter.limits();
        let caches = adapter.features().contains(wgpu::Features::PIPELINE_CACHE);
        let pipeline_cache = if caches {
            pipeline_cache::load(&info)
        } else {
            CacheLoad::Unsupported
        };
        let mut notices = Vec::new();
        if let CacheLoad::Ignored(path, why) = &pipeline_cache {
            notices.push(format!(
                "GPU pipeline cache {}: ignored ({why}); the kernels are compiled and it is rewritten",
                path.display()
            ));
        }
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("pmvc"),
            required_limits: wanted,
            required_features: if caches {
                wgpu::Features::PIPELINE_CACHE
            } else {
                wgpu::Features::empty()
            },
            ..Default::default()
        }))
        .map_err(|e| GpuError::RequestDevice(e.to_string()))?;
        let failure: Arc<Mutex<Option<GpuError>>> = Arc::default();
        // The default handlers panic; record the failure instead and report it from
        // the next operation.
        let lost = Arc::clone(&failure);
        device.set_device_lost_callback(move |reason, message| {
            record(
                &lost,
                GpuError::DeviceLost(format!("{reason:?}: {message}")),
            );
        });
        let uncaptured = Arc::clone(&failure);
        device.on_uncaptured_error(Arc::new(move |error: wgpu::Error| {
            record(&uncaptured, GpuError::from(error));
        }));
        let limits = device.limits();
        Ok(Self {
            device,
            queue,
            info,
            limits,
            failure,
            kernels: OnceLock::new(),
            pipeline_cache,
            opened_in: started.elapsed(),
            notices: Mutex::new(notices),
        })
    }

    /// Wrap a device made elsewhere (the editor's). Its error and device-lost
    /// handlers are left alone; binds catch their own errors with error scopes.
    pub fn from_device(device: wgpu::Device, queue: wgpu::Queue, info: wgpu::AdapterInfo) -> Self {
        let limits = device.limits();
        Self {
            device,
            queue,
            info,
            limits,
            failure: Arc::default(),
            kernels: OnceLock::new(),
            pipeline_cache: CacheLoad::Unsupported,
            opened_in: Duration::ZERO,
            notices: Mutex::default(),
        }
    }

    /// The failure recorded by the device's callbacks, if any.
    pub fn failure(&self) -> Option<GpuError> {
        self.failure.lock().ok().and_then(|slot| slot.clone())
    }

    /// Whether this is a software rasteriser (lavapipe, llvmpipe, WARP).
    pub fn is_software(&self) -> bool {
        self.info.device_type == wgpu::DeviceType::Cpu
    }

    /// One line naming the adapter.
    pub fn describe(&self) -> String {
        describe(&self.info)
    }

    /// What was found of the pipeline cache when the device opened.
    pub fn pipeline_cache(&self) -> &CacheLoad {
        &self.pipeline_cache
    }

    /// How long listing the adapters and opening the device took in this process.
    pub fn opened_in(&self) -> Duration {
        self.opened_in
    }

    /// Whether the binding kernels are compiled already (no start cost left).
    pub fn kernels_ready(&self) -> bool {
        self.kernels.get().is_some_and(Result::is_ok)
    }

    /// The notices about the pipeline cache since the last call, for the user.
    pub fn take_notices(&self) -> Vec<String> {
        self.notices
            .lock()
            .map(|mut notices| std::mem::take(&mut *notices))
            .unwrap_or_default()
    }

    fn notice(&self, line: String) {
        if let Ok(mut notices) = self.notices.lock() {
            notices.push(line);
        }
    }

    pub(super) fn kernels(&self) -> Result<&Kernels, GpuError> {
        self.kernels
            .get_or_init(|| self.compile_kernels())
            .as_ref()
            .map_err(Clone::clone)
    }

    /// Compile the kernels through the pipeline cache where the device keeps one,
    /// then write the cache back when the driver added to it.
    fn compile_kernels(&self) -> Result<Kernels, GpuError> {
        let Some(path) = self.pipeline_cache.path() else {
            return Kernels::new(&self.device, None);
        };
        let known = match &self.pipeline_cache {
            CacheLoad::Hit(_, data) => Some(data.as_slice()),
            _ => None,
        };
        let scope = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        // SAFETY: `known` passed `pipeline_cache::decode`: our header with this
        // adapter's key and wgpu release, and a matching checksum, so it is data
        // `PipelineCache::get_data` returned for this adapter (wgpu checks its own
        // header again; `fallback` starts empty if the driver refuses it).
        let cache = unsafe {
            self.device
                .create_pipeline_cache(&wgpu::PipelineCacheDescriptor {
                    label: Some("pmvc bind"),
                    data: known,
                    fallback: true,
                })
        };
        let cache = match pollster::block_on(scope.pop()) {
            None => Some(cache),
            Some(error) => {
                self.notice(format!(
                    "GPU pipeline cache {}: not used ({error})",
                    path.display()
                ));
                None
            }
        };
        let kernels = Kernels::new(&self.device, cache.as_ref())?;
        if let Some(cache) = &cache {
            self.store_pipeline_cache(cache, known);
        }
        Ok(kernels)
    }

    /// PMVC's band pipeline (for cages with quads where `patches`), compiled on
    /// the first bind that needs one (through the pipeline cache, which is then
    /// written again).
    pub(super) fn pmvc_bands(&self, patches: bool) -> Result<&wgpu::ComputePipeline, GpuError> {
        let kernels = self.kernels()?;
        let before = kernels.pipeline_cache().and_then(|cache| cache.get_data());
        let (pipeline, compiled) = kernels.pmvc_bands(patches);
        if let (true, Some(cache)) = (compiled, kernels.pipeline_cache()) {
            self.store_pipeline_cache(cache, before.as_deref());
        }
        pipeline
    }

    /// Write `cache`'s data to this adapter's cache file unless it is still `known`.
    fn store_pipeline_cache(&self, cache: &wgpu::PipelineCache, known: Option<&[u8]>) {
        let Some(path) = self.pipeline_cache.path() else {
            return;
        };
        let fresh = cache.get_data();
        if let (Some(data), Some(key)) = (fresh, pipeline_cache::adapter_key(&self.info)) {
            if known != Some(data.as_slice()) {
                if let Err(why) = pipeline_cache::store(path, &key, &data) {
                    self.notice(format!(
                        "GPU pipeline cache {}: not written ({why}); the bind goes on",
                        path.display()
                    ));
                }
            }
        }
    }
}

/// False only where no hardware adapter can be opened: on Linux, when `dev` has no GPU
/// device node (`dri/renderD*` or `dri/card*` for Mesa and AMD/Intel drivers,
/// `nvidia*` for NVIDIA's, `dxg` for WSL). Elsewhere always true.
fn may_have_hardware_adapter(dev: &std::path::Path) -> bool {
    if !cfg!(target_os = "linux") {
        return true;
    }
    let has_entry = |dir: &std::path::Path, prefixes: &[&str]| {
        std::fs::read_dir(dir).is_ok_and(|entries| {
            entries.flatten().any(|entry| {
                let name = entry.file_name();
                let name = name.to_string_lossy();
                prefixes.iter().any(|prefix| name.starts_with(prefix))
            })
        })
    };
    has_entry(&dev.join("dri"), &["renderD", "card"]) || has_entry(dev, &["nvidia", "dxg"])
}

fn record(slot: &Mutex<Option<GpuError>>, error: GpuError) {
    if let Ok(mut slot) = slot.lock() {
        slot.get_or_insert(error);
    }
}

/// The backends listed without `WGPU_BACKEND`: the native APIs only. GL through
/// EGL adds a slow driver load and, where a native backend exists, nothing usable.
pub const DEFAULT_BACKENDS: wgpu::Backends = wgpu::Backends::PRIMARY;

fn make_instance() -> wgpu::Instance {
    let mut descriptor = wgpu::InstanceDescriptor::new_without_display_handle();
    descriptor.backends = DEFAULT_BACKENDS;
    // `WGPU_BACKEND` (and the other WGPU_* instance variables) override it.
    wgpu::Instance::new(descriptor.with_env())
}

/// Lower is better: discrete, integrated, virtual, unknown, then software.
fn device_rank(device_type: wgpu::DeviceType) -> u8 {
    match device_type {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Other => 3,
        wgpu::DeviceType::Cpu => 4,
    }
}

/// Lower is better among adapters of the same kind: native APIs before GL.
fn backend_rank(backend: wgpu::Backend) -> u8 {
    match backend {
        wgpu::Backend::Vulkan | wgpu::Backend::Metal | wgpu::Backend::Dx12 => 0,
        wgpu::Backend::Gl => 1,
        _ => 2,
    }
}

fn can_compute(adapter: &wgpu::Adapter) -> bool {
    adapter
        .get_downlevel_capabilities()
        .flags
        .contains(wgpu::DownlevelFlags::COMPUTE_SHADERS)
}

/// The adapter policy: `WGPU_ADAPTER_NAME` (case-insensitive substring) when set,
/// else the best compute-capable adapter by kind (high performance first), software
/// adapters last.
fn choose_adapter(adapters: Vec<wgpu::Adapter>) -> Result<wgpu::Adapter, GpuError> {
    let usable: Vec<wgpu::Adapter> = adapters.into_iter().filter(can_compute).collect();
    if let Ok(name) = std::env::var("WGPU_ADAPTER_NAME") {
        let wanted = name.to_lowercase();
        return usable
            .into_iter()
            .find(|a| a.get_info().name.to_lowercase().contains(&wanted))
            .ok_or_else(|| {
                GpuError::NoAdapter(format!("none matches WGPU_ADAPTER_NAME={name:?}"))
            });
    }
    usable
        .into_iter()
        .min_by_key(|a| {
            let info = a.get_info();
            (device_rank(info.device_type), backend_rank(info.backend))
        })
        .ok_or_else(|| GpuError::NoAdapter("no compute-capable adapter found".into()))
}

fn describe(info: &wgpu::AdapterInfo) -> String {
    format!(
        "{} ({:?}, {:?}, driver {} {})",
        info.name, info.device_type, info.backend, info.driver, info.driver_info
    )
}

/// Every adapter, the one [`GpuContext::new`] would choose, and the limits that
/// bound a bind, for `pmvc info`.
pub fn adapters_report() -> String {
    let instance = make_instance();
    let adapters = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::all()));
    let mut report = String::new();
    let backend_env = std::env::var("WGPU_BACKEND")
        .unwrap_or_else(|_| "(unset: Vulkan, Metal, DX12; not GL)".into());
    let name_env = std::env::var("WGPU_ADAPTER_NAME").unwrap_or_else(|_| "(unset)".into());
    let _ = writeln!(
        report,
        "GPU adapters (WGPU_BACKEND={backend_env}, WGPU_ADAPTER_NAME={name_env}):"
    );
    if adapters.is_empty() {
        let _ = writeln!(report, "  none");
    }
    for adapter in &adapters {
        let compute = if can_compute(adapter) {
            ""
        } else {
            " [no compute shaders]"
        };
        let _ = writeln!(report, "  - {}{compute}", describe(&adapter.get_info()));
    }
    match choose_adapter(adapters) {
        Ok(adapter) => {
            let limits = adapter.limits();
            let info = adapter.get_info();
            let _ = writeln!(report, "chosen: {}", describe(&info));
            let cache = if adapter.features().contains(wgpu::Features::PIPELINE_CACHE) {
                pipeline_cache::load(&info)
            } else {
                CacheLoad::Unsupported
            };
            let _ = writeln!(report, "  pipeline cache: {}", cache.describe());
            let _ = writeln!(
                report,
                "  max storage buffer binding size: {} bytes ({} MiB)",
                limits.max_storage_buffer_binding_size,
                limits.max_storage_buffer_binding_size >> 20
            );
            let _ = writeln!(
                report,
                "  max buffer size: {} bytes ({} MiB)",
                limits.max_buffer_size,
                limits.max_buffer_size >> 20
            );
            let _ = writeln!(
                report,
                "  max storage buffers per shader stage: {}",
                limits.max_storage_buffers_per_shader_stage
            );
            let _ = writeln!(
                report,
                "  max compute workgroup size: {} x {} x {}, {} invocations",
                limits.max_compute_workgroup_size_x,
                limits.max_compute_workgroup_size_y,
                limits.max_compute_workgroup_size_z,
                limits.max_compute_invocations_per_workgroup
            );
            let _ = writeln!(
                report,
                "  max compute workgroups per dimension: {}",
                limits.max_compute_workgroups_per_dimension
            );
            let _ = writeln!(
                report,
                "  max compute workgroup storage: {} bytes",
                limits.max_compute_workgroup_storage_size
            );
        }
        Err(error) => {
            let _ = writeln!(report, "chosen: none ({error})");
        }
    }
    report
}

#[cfg(test)]
mod tests {
    use super::may_have_hardware_adapter;

    #[test]
    #[cfg(target_os = "linux")]
    fn a_gpu_device_node_is_what_makes_a_hardware_adapter_possible() {
        let dev = tempfile::tempdir().expect("a temporary folder");
        let touch = |name: &str| std::fs::write(dev.path().join(name), b"").expect("a file");
        touch("null");
        touch("tty0");
        std::fs::create_dir(dev.path().join("dri")).expect("a folder");
        assert!(!may_have_hardware_adapter(dev.path()), "no GPU node yet");
        touch("dri/by-path");
        assert!(!may_have_hardware_adapter(dev.path()), "no GPU node yet");
        for node in ["dri/renderD128", "dri/card0", "nvidia0", "nvidiactl", "dxg"] {
            touch(node);
            assert!(may_have_hardware_adapter(dev.path()), "{node}");
            std::fs::remove_file(dev.path().join(node)).expect("removed");
            assert!(!may_have_hardware_adapter(dev.path()), "{node} removed");
        }
    }
}
