//! The cost model's choices on given figures (not timings).

use super::*;

fn work(method: Method, points: usize, cage_vertices: usize, cpu_threads: usize) -> Work {
    Work {
        method,
        points,
        texels: if method == Method::Pmvc {
            6 * 32 * 32
        } else {
            0
        },
        cage_triangles: 2 * cage_vertices - 4,
        cage_vertices,
        cage_quads: 0,
        cpu_threads,
        pmvc_exact: false,
    }
}

fn device(class: AdapterClass, pipelines: Pipelines) -> GpuState {
    GpuState {
        class,
        pipelines,
        start_s: 0.0,
    }
}

#[test]
fn a_tiny_bind_goes_to_the_cpu_and_a_large_one_to_a_discrete_gpu() {
    let cold = device(AdapterClass::Discrete, Pipelines::Cold);
    let tiny = predict(&work(Method::Pmvc, 500, 110, 16), &cold);
    assert!(!tiny.gpu_wins(), "{}", tiny.explain());
    let large = predict(&work(Method::Pmvc, 200_000, 110, 16), &cold);
    assert!(large.gpu_wins(), "{}", large.explain());
}

#[test]
fn the_pipeline_cache_and_compiled_kernels_move_the_break_even_down() {
    // Four times Armadillo size on 16 threads: the start decides it (at Armadillo
    // size the H200's whole process lost to the CPU even with the cache hit).
    let scene = work(Method::Pmvc, 60_000, 110, 16);
    let cold = predict(&scene, &device(AdapterClass::Discrete, Pipelines::Cold));
    let hit = predict(&scene, &device(AdapterClass::Discrete, Pipelines::CacheHit));
    let ready = predict(&scene, &device(AdapterClass::Discrete, Pipelines::Ready));
    assert!(!cold.gpu_wins(), "{}", cold.explain());
    assert!(hit.gpu_wins(), "{}", hit.explain());
    assert!(ready.gpu_wins(), "{}", ready.explain());
    assert!(ready.gpu_s < hit.gpu_s && hit.gpu_s < cold.gpu_s);
    assert_eq!(cold.cpu_s, hit.cpu_s, "the CPU's side has no start");
}

#[test]
fn a_device_still_to_open_counts_its_start() {
    let scene = work(Method::Pmvc, 40_000, 110, 16);
    let open = device(AdapterClass::Discrete, Pipelines::Ready);
    let closed = GpuState {
        start_s: 1.0,
        ..open
    };
    assert!(predict(&scene, &open).gpu_wins());
    assert!(!predict(&scene, &closed).gpu_wins());
}

#[test]
fn a_software_adapter_never_wins_pmvc_against_two_cpu_threads() {
    for pipelines in [Pipelines::Ready, Pipelines::CacheHit, Pipelines::Cold] {
        for points in [1, 1_000, 15_002, 1_000_000] {
            for vertices in [8, 110, 1_523] {
                for threads in [2, 4, 16] {
                    let prediction = predict(
                        &work(Method::Pmvc, points, vertices, threads),
                        &device(AdapterClass::Software, pipelines),
                    );
                    assert!(!prediction.gpu_wins(), "{}", prediction.explain());
                }
            }
        }
    }
}

/// Harmonic coordinates, MEC, MLC and any family added without a kernel.
#[test]
fn families_without_a_kernel_always_bind_on_the_cpu() {
    let cpu_only: Vec<Method> = Method::ALL
        .into_iter()
        .filter(|&method| Kernel::of(method).is_none())
        .collect();
    for family in [
        Method::Harmonic,
        Method::Mec,
        Method::Mlc,
        Method::Bbw,
        Method::Lbc,
    ] {
        assert!(cpu_only.contains(&family), "{family}");
    }
    for method in cpu_only {
        let scene = work(method, 10_000_000, 1_523, 1);
        let prediction = predict(&scene, &device(AdapterClass::Discrete, Pipelines::Ready));
        assert_eq!(prediction.gpu_s, None);
        assert!(!prediction.gpu_wins());
        assert!(
            prediction.explain().contains("no GPU kernel"),
            "{}",
            prediction.explain()
        );
        assert_eq!(
            scene.no_kernel_reason(),
            Some("this family has no GPU kernel")
        );
        assert!(!decide(BackendRequest::Auto, None, &scene).on_gpu(method));
    }
}

#[test]
fn more_cpu_threads_keep_more_binds_on_the_cpu() {
    let gpu = device(AdapterClass::Discrete, Pipelines::CacheHit);
    let two = predict(&work(Method::Mvc, 20_000, 51, 2), &gpu);
    let many = predict(&work(Method::Mvc, 20_000, 51, 64), &gpu);
    assert!(two.gpu_wins(), "{}", two.explain());
    assert!(!many.gpu_wins(), "{}", many.explain());
}

#[test]
fn an_integrated_gpu_needs_more_work_than_a_discrete_one() {
    let scene = work(Method::Pmvc, 30_000, 110, 8);
    let discrete = predict(&scene, &device(AdapterClass::Discrete, Pipelines::CacheHit));
    let integrated = predict(
        &scene,
        &device(AdapterClass::Integrated, Pipelines::CacheHit),
    );
    assert!(discrete.gpu_wins(), "{}", discrete.explain());
    assert!(!integrated.gpu_wins(), "{}", integrated.explain());
}

#[test]
fn requests_parse_from_their_names_only() {
    for name in BackendRequest::NAMES {
        assert!(BackendRequest::from_name(name).is_some(), "{name}");
    }
    assert_eq!(BackendRequest::from_name("GPU"), None);
    assert_eq!(BackendRequest::from_name(""), None);
}

#[test]
fn auto_decides_a_bind_the_best_gpu_would_lose_before_opening_any_device() {
    let tiny = work(Method::Pmvc, 100, 110, 16);
    let decision = decide_and_open(BackendRequest::Auto, &tiny).expect("no device needed");
    assert!(matches!(decision.backend, Backend::Cpu));
    // Decided on the best case, device still to open: no driver was loaded.
    let prediction = decision.prediction.expect("the model's figures");
    assert_eq!(prediction.gpu.start_s, HARDWARE_START_S);
    assert!(!prediction.gpu_wins(), "{}", prediction.explain());
}

#[test]
fn auto_without_a_hardware_adapter_says_so() {
    let large = work(Method::Pmvc, 1_000_000, 110, 2);
    let decision = decide(BackendRequest::Auto, None, &large);
    assert!(matches!(decision.backend, Backend::Cpu));
    assert_eq!(
        decision.explain(),
        "binding on the CPU: no hardware GPU adapter"
    );
    let asked_for_cpu = decide(BackendRequest::Cpu, None, &large);
    assert_eq!(asked_for_cpu.explain(), "binding on the CPU");
}

#[test]
fn mvc_on_a_cage_with_quads_is_qmvc_and_binds_on_the_cpu_saying_why() {
    let quads = Work {
        cage_quads: 6,
        ..work(Method::Mvc, 10_000_000, 8, 1)
    };
    assert_eq!(quads.kernel(), None);
    let prediction = predict(&quads, &device(AdapterClass::Discrete, Pipelines::Ready));
    assert!(!prediction.gpu_wins());
    assert!(
        prediction.explain().contains("QMVC"),
        "{}",
        prediction.explain()
    );
    let decision = decide(BackendRequest::Cpu, None, &quads);
    assert!(!decision.on_gpu(Method::Mvc));
    // PMVC keeps its kernel on the same cage; Green there is QGC, which has none.
    let pmvc = Work {
        method: Method::Pmvc,
        ..quads
    };
    assert!(pmvc.kernel().is_some());
    assert_eq!(pmvc.no_kernel_reason(), None);
    let green = Work {
        method: Method::Green,
        ..quads
    };
    assert_eq!(green.kernel(), None);
    assert!(green
        .no_kernel_reason()
        .is_some_and(|why| why.contains("QGC")));
}

#[test]
fn work_counts_the_quads_a_family_binds_as_patches() {
    let cage = crate::geometry::procedural_quads::twisted_box(2.0, 0.6);
    let mvc = Work::of(BindOptions::for_method(Method::Mvc), 10, &cage);
    assert_eq!((mvc.cage_quads, mvc.kernel()), (6, None));
    let split = BindOptions {
        quads: crate::geometry::QuadSplit::Shorter,
        ..BindOptions::for_method(Method::Mvc)
    };
    assert_eq!(Work::of(split, 10, &cage).kernel(), Some(Kernel::Mvc));
    let green = Work::of(BindOptions::for_method(Method::Green), 10, &cage);
    assert_eq!((green.cage_quads, green.kernel()), (6, None));
    let green_split = BindOptions {
        quads: crate::geometry::QuadSplit::Shorter,
        ..BindOptions::for_method(Method::Green)
    };
    assert_eq!(
        Work::of(green_split, 10, &cage).kernel(),
        Some(Kernel::Green)
    );
}

#[test]
fn patches_cost_the_cpu_more_than_the_gpu_so_the_gpu_wins_sooner() {
    let ready = device(AdapterClass::Discrete, Pipelines::Ready);
    // A 110-vertex cage on two threads, few enough points that its split binds
    // on the CPU.
    let split = work(Method::Pmvc, 600, 110, 2);
    let patches = Work {
        cage_quads: split.cage_triangles / 2,
        ..split
    };
    let (on_split, on_patches) = (predict(&split, &ready), predict(&patches, &ready));
    assert!(!on_split.gpu_wins(), "{}", on_split.explain());
    assert!(on_patches.gpu_wins(), "{}", on_patches.explain());
    let cpu_ratio = on_patches.cpu_s.unwrap() / on_split.cpu_s.unwrap();
    assert!((cpu_ratio - 3.0).abs() < 1e-9, "{cpu_ratio}");
    // A few quads among many triangles cost nearly the split.
    let few = Work {
        cage_quads: 2,
        ..split
    };
    let few_ratio = predict(&few, &ready).cpu_s.unwrap() / on_split.cpu_s.unwrap();
    assert!(few_ratio < 1.05, "{few_ratio}");
    // A software adapter pays lavapipe's ratio, not the CPU path's.
    let software = device(AdapterClass::Software, Pipelines::Ready);
    let gpu = |w: &Work| predict(w, &software).gpu_s.unwrap();
    let software_ratio = gpu(&patches) / gpu(&split);
    assert!((software_ratio - 1.6).abs() < 1e-9, "{software_ratio}");
}

/// PMVC 32² on Table 2's 24,795 points in a cage of `vertices` vertices.
fn sphere_of(vertices: usize) -> Work {
    work(Method::Pmvc, 24_795, vertices, 16)
}

#[test]
fn auto_takes_the_tile_kernel_for_mid_sized_cages_of_triangles_and_bands_otherwise() {
    // Table 1's Horse size (98 triangles) and Hand size (500): tiles were faster
    // on the H200; Table 2's 1,523-vertex sphere (3,042) and the 12-triangle
    // box cages: bands.
    let horse = work(Method::Pmvc, 48_485, 51, 16);
    let hand = work(Method::Pmvc, 24_795, 252, 16);
    let sphere = sphere_of(1_523);
    let cube = work(Method::Pmvc, 60_802, 8, 16);
    assert_eq!(PmvcKernel::Auto.takes_tiles(&horse), Ok(true));
    assert_eq!(PmvcKernel::Auto.takes_tiles(&hand), Ok(true));
    // --verbose says which kernel the GPU's prediction is for.
    let ready = device(AdapterClass::Discrete, Pipelines::Ready);
    let said = predict(&horse, &ready).explain();
    assert!(
        said.contains("(discrete, PMVC tile kernel, kernels compiled)"),
        "{said}"
    );
    let said = predict(&sphere_of(1_523), &ready).explain();
    assert!(
        said.contains("(discrete, PMVC band kernel, kernels compiled)"),
        "{said}"
    );
    assert_eq!(PmvcKernel::Auto.takes_tiles(&sphere), Ok(false));
    assert_eq!(PmvcKernel::Auto.takes_tiles(&cube), Ok(false));
    // Asked for by name, each kernel binds whatever the model prefers...
    assert_eq!(PmvcKernel::Tiles.takes_tiles(&sphere), Ok(true));
    assert_eq!(PmvcKernel::Bands.takes_tiles(&horse), Ok(false));
    // ...except tiles on a cage they cannot hold: patches, or too many vertices.
    let patches = Work {
        cage_quads: 6,
        ..work(Method::Pmvc, 1_000, 8, 16)
    };
    assert_eq!(PmvcKernel::Auto.takes_tiles(&patches), Ok(false));
    let why = PmvcKernel::Tiles.takes_tiles(&patches).unwrap_err();
    assert!(why.contains("bilinear patches"), "{why}");
    let large = work(Method::Pmvc, 1_000, 2_100, 16);
    assert_eq!(PmvcKernel::Auto.takes_tiles(&large), Ok(false));
    let why = PmvcKernel::Tiles.takes_tiles(&large).unwrap_err();
    assert!(why.contains("2100") && why.contains("2048"), "{why}");
}

#[test]
fn the_gpu_prediction_follows_the_kernel_auto_picks() {
    // The H200's `pmvc bench` medians (2026-11-28), bind only: Horse size 0.047 s
    // by tiles (0.075 by bands), the 1,523-vertex sphere 0.180 s by bands (0.374
    // by tiles). The model's per-point part must land within 30% of the faster.
    let ready = device(AdapterClass::Discrete, Pipelines::Ready);
    for (scene, measured) in [
        (work(Method::Pmvc, 48_485, 51, 16), 0.047),
        (work(Method::Pmvc, 24_795, 1_523, 16), 0.180),
    ] {
        let points_s = predict(&scene, &ready).gpu_s.expect("PMVC has a kernel") - GPU_BIND_FIXED_S;
        assert!(
            (0.7 * measured..1.3 * measured).contains(&points_s),
            "{} points, {} vertices: predicted {points_s:.3} s, measured {measured} s",
            scene.points,
            scene.cage_vertices
        );
    }
}
