//! `kanegen bench` report shape (no timing assertions: speed goals live in the report itself,
//! measured side by side, never in tests).

#[test]
fn bench_reports_every_candidate_with_ratios_to_generated() {
    let r = kanegen::cli::commands::bench::bench_ssrms(3, 20, 13).unwrap();
    assert_eq!(r.n, 7);
    for f in [
        "M+c",
        "forward_dynamics",
        "inverse_dynamics",
        "free-floating forward_dynamics",
    ] {
        let lines: Vec<_> = r.results.iter().filter(|l| l.function == f).collect();
        assert!(lines.len() >= 3, "{f}: {} candidates", lines.len());
        assert_eq!(lines[0].name, "generated");
        assert_eq!(lines[0].ratio_to_first, 1.0);
        for l in lines {
            assert!(l.ns.is_finite() && l.ns > 0.0, "{f} {}: {}", l.name, l.ns);
            assert!(l.ns_range[0] <= l.ns && l.ns <= l.ns_range[1]);
        }
    }
    // States per second: one state, lanes and all cores for each generated function.
    let t = &r.throughput;
    assert_eq!((t.batch, t.rounds), (13, 3));
    assert!(t.threads >= 1);
    let functions: Vec<&str> = t.lines.iter().map(|l| l.function.as_str()).collect();
    assert_eq!(
        functions,
        [
            "mass_matrix",
            "nonlinear_effects",
            "mass_matrix_and_nonlinear_effects",
            "inverse_dynamics",
            "forward_dynamics",
            "forward_dynamics_derivatives"
        ]
    );
    for l in &t.lines {
        let rates = [l.one_state, l.f64x2, l.f64x4, l.cores_f64x2, l.cores_f64x4];
        assert!(rates.iter().all(|x| x.is_finite() && *x > 0.0), "{l:?}");
        assert_eq!(l.lanes_ratio, l.f64x2.max(l.f64x4) / l.one_state);
        assert_eq!(
            l.cores_ratio,
            l.cores_f64x2.max(l.cores_f64x4) / l.f64x2.max(l.f64x4)
        );
    }
    let text = kanegen::cli::commands::bench::render_text(&r);
    assert!(text.contains("Throughput, 13 states per batch"), "{text}");
    assert!(text.contains("forward_dynamics_derivatives"));
    let json = serde_json::to_value(&r).unwrap();
    assert!(json["results"][0]["ns"].is_number());
    assert!(json["throughput"]["lines"][4]["cores_f64x4"].is_number());
}
