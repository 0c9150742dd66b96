//! `kanegen bench` report shape (no timing assertions: speed goals live in the report itself,
//! measured side by side, never in tests).

#[test]
fn bench_reports_every_candidate_with_ratios_to_generated() {
    let r = kanegen::cli::commands::bench::bench_ssrms(3, 20).unwrap();
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
    let json = serde_json::to_value(&r).unwrap();
    assert!(json["results"][0]["ns"].is_number());
}
