//! The editor's bind queue follows the one backend rule: with `auto` on a device
//! the cost model does not favour (lavapipe on CI), a job binds on the CPU and
//! leaves no resident GPU copy, so the viewport uploads the CPU weights; with
//! `gpu` the same device binds and keeps its copy. Without an adapter the test
//! prints "not run", unless `PMVC_REQUIRE_GPU=1`. And `pmvc info` lists the native
//! backends only, unless `WGPU_BACKEND` names others.

use pmvc::app::bind_queue::{BindQueue, Finished};
use pmvc::coords::{BindOptions, Method};
use pmvc::geometry::procedural;
use pmvc::gpu::{Backend, BackendRequest, GpuContext};
use std::sync::Arc;
use std::time::Duration;

fn device() -> Option<Arc<GpuContext>> {
    match GpuContext::new() {
        Ok(context) => Some(Arc::new(context)),
        Err(error) if std::env::var("PMVC_REQUIRE_GPU").as_deref() == Ok("1") => {
            panic!("PMVC_REQUIRE_GPU=1 but no GPU: {error}")
        }
        Err(error) => {
            println!("not run: no GPU adapter ({error})");
            None
        }
    }
}

fn bind_once(context: &Arc<GpuContext>, request: BackendRequest) -> Finished {
    let cage = procedural::extrude(&procedural::comb_outline(4, 1.0, 0.25, 3.0), -0.5, 0.5);
    let points = procedural::points_inside(&cage, 300, 5, 1e-3);
    let mut queue = BindQueue::new(Backend::Gpu(Arc::clone(context)), request, || {});
    queue.set_scene(points.into(), Arc::new(cage));
    assert!(queue.request(BindOptions::for_method(Method::Pmvc)));
    let mut finished = None;
    for _ in 0..600 {
        finished = queue.wait(Duration::from_millis(100));
        if finished.is_some() {
            break;
        }
    }
    finished.expect("the bind ends within a minute")
}

#[test]
fn auto_binds_on_the_cpu_where_the_model_says_so_and_gpu_keeps_the_device() {
    let Some(context) = device() else {
        return;
    };
    let auto = bind_once(&context, BackendRequest::Auto);
    let outcome = auto.result.as_ref().expect("the auto bind");
    if context.is_software() {
        assert!(!auto.on_gpu, "a software adapter never wins PMVC");
        assert_eq!(outcome.device, "CPU");
        assert!(
            outcome.resident.is_none(),
            "the viewport uploads the CPU weights"
        );
    }
    let gpu = bind_once(&context, BackendRequest::Gpu);
    let outcome = gpu.result.as_ref().expect("the GPU bind");
    assert!(gpu.on_gpu);
    assert_ne!(outcome.device, "CPU");
    assert!(
        outcome.resident.is_some(),
        "a GPU bind leaves its copy on the device"
    );
}

fn info(backend: Option<&str>) -> String {
    let mut command = std::process::Command::new(env!("CARGO_BIN_EXE_pmvc"));
    command.arg("info").env_remove("WGPU_BACKEND");
    if let Some(backend) = backend {
        command.env("WGPU_BACKEND", backend);
    }
    let output = command.output().expect("run pmvc info");
    assert_eq!(output.status.code(), Some(0));
    String::from_utf8_lossy(&output.stdout).into_owned()
}

/// The adapters `pmvc info` lists, each line's backend.
fn listed_backends(report: &str) -> Vec<String> {
    report
        .lines()
        .filter_map(|line| line.strip_prefix("  - "))
        // "NAME (TYPE, BACKEND, driver …)"
        .filter_map(|adapter| {
            let head = &adapter[..adapter.find(", driver")?];
            head.rsplit(", ").next().map(str::to_owned)
        })
        .collect()
}

#[test]
fn only_native_backends_are_listed_unless_wgpu_backend_says_otherwise() {
    let native = info(None);
    assert!(
        native.contains("unset: Vulkan, Metal, DX12; not GL"),
        "{native}"
    );
    let backends = listed_backends(&native);
    assert!(
        backends
            .iter()
            .all(|backend| ["Vulkan", "Metal", "Dx12"].contains(&backend.as_str())),
        "{native}"
    );
    let gl = info(Some("gl"));
    assert!(gl.contains("WGPU_BACKEND=gl,"), "{gl}");
    assert!(
        listed_backends(&gl).iter().all(|backend| backend == "Gl"),
        "{gl}"
    );
}
