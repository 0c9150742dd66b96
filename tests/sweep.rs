//! Sweeps and shards (`kanegen sweep`, `kanegen merge`, `kanegen_sim::sweep`): shards merge
//! into the unsharded files byte for byte, a run's numbers depend on the seed and its index
//! only, a run is the scene with its numbers written in by hand, the grid is the product of the
//! values, and bad sweep files, bad draws and wrong shard sets are named.

mod common;

use common::root;
use kanegen::sim::scene::Scene;
use kanegen::sim::simulate::{simulate, Run};
use kanegen::sim::sweep::{Outcome, Shard, Sweep};
use std::path::{Path, PathBuf};

/// A fresh scratch directory for `name`.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("kanegen-sweep-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Runs the CLI in process; its stdout, or the error's chain.
fn cli(args: &[&str]) -> Result<String, String> {
    let mut out = Vec::new();
    let mut argv = vec!["kanegen"];
    argv.extend(args);
    kanegen::cli::app::run_args(argv, &mut out)
        .map(|()| String::from_utf8(out).unwrap())
        .map_err(|e| format!("{e:#}"))
}

fn ok(args: &[&str]) -> String {
    cli(args).unwrap_or_else(|e| panic!("{args:?}: {e}"))
}

fn example() -> String {
    root()
        .join("scenes/sweeps/capture.toml")
        .display()
        .to_string()
}

fn read(d: &Path, f: &str) -> String {
    std::fs::read_to_string(d.join(f)).unwrap()
}

/// A sweep file in `dir` over the capture scene, with `body` after the scene line.
fn sweep_file(dir: &Path, body: &str) -> String {
    let scene = root().join("scenes/capture_free_floating.toml");
    let p = dir.join("sweep.toml");
    std::fs::write(
        &p,
        format!("scene = {:?}\n{body}", scene.display().to_string()),
    )
    .unwrap();
    p.display().to_string()
}

#[test]
fn shards_merge_into_the_unsharded_files_byte_for_byte() {
    let d = scratch("merge");
    let whole = d.join("whole");
    ok(&["sweep", &example(), "--out", whole.to_str().unwrap()]);
    for count in [3_u64, 5] {
        let mut dirs = Vec::new();
        // Shards in reverse order, as a scheduler may finish them.
        for i in (0..count).rev() {
            let s = d.join(format!("s{count}-{i}"));
            ok(&[
                "sweep",
                &example(),
                "--shard",
                &format!("{i}/{count}"),
                "--out",
                s.to_str().unwrap(),
            ]);
            dirs.push(s.display().to_string());
        }
        let m = d.join(format!("merged{count}"));
        let mut args = vec!["merge"];
        args.extend(dirs.iter().map(String::as_str));
        args.extend(["--out", m.to_str().unwrap()]);
        ok(&args);
        for f in ["runs.csv", "sweep.json"] {
            assert_eq!(read(&m, f), read(&whole, f), "{count} shards: {f}");
        }
    }
    let runs = read(&whole, "runs.csv");
    assert_eq!(runs.lines().count(), 65, "a header and 64 runs");
    assert!(runs.lines().skip(1).all(|l| l.contains(",complete,")));
}

#[test]
fn merge_names_missing_repeated_and_foreign_shards() {
    let d = scratch("bad-merge");
    let shard = |sweep: &str, i: u64, n: u64, name: &str| {
        let s = d.join(name);
        ok(&[
            "sweep",
            sweep,
            "--shard",
            &format!("{i}/{n}"),
            "--out",
            s.to_str().unwrap(),
        ]);
        s.display().to_string()
    };
    let a = shard(&example(), 0, 4, "a");
    let b = shard(&example(), 2, 4, "b");
    let out = d.join("m").display().to_string();
    let e = cli(&["merge", &a, &b, "--out", &out]).unwrap_err();
    assert!(
        e.contains("shards missing, of 4: 1 (runs 16..32), 3 (runs 48..64)"),
        "{e}"
    );
    let e = cli(&["merge", &a, &a, "--out", &out]).unwrap_err();
    assert!(e.contains("shard 0/4 given twice"), "{e}");
    let other = sweep_file(
        &d,
        "runs = 4\nseed = 9\n[[parameter]]\nkey = \"events[0].mass\"\nuniform = [50.0, 60.0]\n",
    );
    let c = shard(&other, 1, 4, "c");
    let e = cli(&["merge", &a, &c, "--out", &out]).unwrap_err();
    assert!(e.contains("is not a shard of the sweep of"), "{e}");
    // A damaged runs.csv is named with its line.
    let csv = std::path::Path::new(&b).join("runs.csv");
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines: Vec<&str> = text.lines().collect();
    let cut = lines[3].rsplit_once(',').unwrap().0.to_string();
    lines[3] = &cut;
    std::fs::write(&csv, lines.join("\n")).unwrap();
    let e = cli(&["merge", &b, "--out", &out]).unwrap_err();
    assert!(e.contains("runs.csv line 4: "), "{e}");
}

#[test]
fn a_run_is_the_scene_with_its_numbers_written_in() {
    let sweep = Sweep::load(Path::new(&example())).unwrap();
    let k = 37;
    let v = sweep.values(k);
    let SweepRun {
        outcome: Outcome::Ran { summary, last },
        ..
    } = sweep.run(k, None)
    else {
        panic!("run {k} did not run");
    };
    // The scene file with the three numbers replaced by hand.
    let text = std::fs::read_to_string(root().join("scenes/capture_free_floating.toml")).unwrap();
    let text = text
        .replacen("mass = 80.0", &format!("mass = {:?}", v[0]), 1)
        .replacen(
            "omega = [0.1, -0.05, 0.08]",
            &format!("omega = [0.1, -0.05, {:?}]", v[1]),
            1,
        )
        .replacen(
            "v = [0.05, -0.03, 0.02]",
            &format!("v = [{:?}, -0.03, 0.02]", v[2]),
            1,
        );
    let scene = Scene::parse(&text, &root().join("scenes")).unwrap();
    let Run {
        summary: s,
        samples,
    } = simulate(&scene, None).unwrap();
    assert_eq!(s.final_state.q, summary.final_state.q);
    assert_eq!(s.final_state.qd, summary.final_state.qd);
    assert_eq!(samples.last().unwrap().x, last.x);
    assert_eq!(s.events.len(), 2);
    assert_eq!(s.events[0].energy_change, summary.events[0].energy_change);
    // The nominal scene's run differs: the numbers were changed.
    let nominal = simulate(
        &kanegen::sim::scene::Scene::load(&sweep.scene_path).unwrap(),
        None,
    )
    .unwrap()
    .summary;
    assert_ne!(nominal.final_state.q, summary.final_state.q);
}

use kanegen::sim::sweep::SweepRun;

#[test]
fn draws_depend_on_seed_and_index_only_and_the_grid_is_the_product() {
    let d = scratch("draws");
    let body = "runs = 50\nseed = 11\n\
        [[parameter]]\nkey = \"drives.kp\"\nvalues = [5.0, 20.0, 40.0]\n\
        [[parameter]]\nkey = \"events[0].mass\"\nuniform = [50.0, 60.0]\n\
        [[parameter]]\nkey = \"simulation.output_every\"\nvalues = [5, 10]\n\
        [[parameter]]\nkey = \"events[0].v[1]\"\nnormal = { mean = -0.03, std = 0.01 }\n";
    let s = Sweep::load(Path::new(&sweep_file(&d, body))).unwrap();
    assert_eq!((s.grid_points(), s.runs()), (6, 300));
    let all: Vec<Vec<f64>> = (0..s.runs()).map(|k| s.values(k)).collect();
    for (k, v) in all.iter().enumerate() {
        let point = k / 50;
        assert_eq!(v[0], [5.0, 20.0, 40.0][point / 2], "run {k}");
        assert_eq!(v[2], [5.0, 10.0][point % 2], "run {k}");
        assert!((50.0..60.0).contains(&v[1]), "run {k}: {}", v[1]);
    }
    // The normal draws: mean and spread within 5 standard errors of 300 samples.
    let n: Vec<f64> = all.iter().map(|v| v[3]).collect();
    let mean = n.iter().sum::<f64>() / 300.0;
    let sd = (n.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / 299.0).sqrt();
    assert!((mean + 0.03).abs() < 5.0 * 0.01 / 300f64.sqrt(), "{mean}");
    assert!((sd - 0.01).abs() < 5.0 * 0.01 / 600f64.sqrt(), "{sd}");
    // Another seed draws other numbers, the same grid.
    let s2 = Sweep::load(Path::new(&sweep_file(
        &d,
        &body.replace("seed = 11", "seed = 12"),
    )))
    .unwrap();
    let v2 = s2.values(7);
    assert_ne!(v2[1], all[7][1]);
    assert_eq!((v2[0], v2[2]), (all[7][0], all[7][2]));
    // A shard's runs are a contiguous block; the blocks cover the sweep once.
    let mut next = 0;
    for i in 0..7 {
        let r = Shard { index: i, count: 7 }.runs(300);
        assert_eq!(r.start, next);
        next = r.end;
    }
    assert_eq!(next, 300);
    assert_eq!(
        Shard::parse("3/16").unwrap(),
        Shard {
            index: 3,
            count: 16
        }
    );
    for bad in ["16/16", "3", "a/4", "-1/4"] {
        assert!(Shard::parse(bad).is_err(), "{bad}");
    }
}

#[test]
fn an_invalid_draw_is_a_failed_run_named_by_its_key() {
    let d = scratch("invalid");
    let f = sweep_file(
        &d,
        "runs = 40\nseed = 3\n[[parameter]]\nkey = \"events[0].mass\"\nnormal = { mean = 1.0, std = 2.0 }\n",
    );
    let out = d.join("out");
    let text = ok(&["sweep", &f, "--out", out.to_str().unwrap()]);
    let report: serde_json::Value = serde_json::from_str(&read(&out, "sweep.json")).unwrap();
    let invalid = report["invalid"].as_u64().unwrap();
    assert!(invalid > 0 && invalid < 40, "{invalid}");
    assert_eq!(report["complete"].as_u64().unwrap() + invalid, 40);
    let failures = report["failures"].as_array().unwrap();
    assert_eq!(failures.len() as u64, invalid);
    let reason = failures[0]["reason"].as_str().unwrap();
    assert!(
        reason.contains("events[0].mass") && reason.contains("must be > 0"),
        "{reason}"
    );
    assert!(text.contains("invalid"), "{text}");
    // Its row keeps the drawn number and leaves the rest empty.
    let run = failures[0]["run"].as_u64().unwrap();
    let csv = read(&out, "runs.csv");
    let row = csv.lines().nth(run as usize + 1).unwrap();
    assert!(row.starts_with(&format!("{run},invalid,-")), "{row}");
    assert!(row.ends_with(",,,"), "{row}");
}

#[test]
fn bad_sweep_files_are_named_with_their_line() {
    let d = scratch("bad-files");
    let cases = [
        (
            "key = \"events[2].mass\"\nuniform = [1.0, 2.0]",
            "parameter[0] (line 2): key `events[2].mass`: index [2] out of range: the scene has 2",
        ),
        (
            "key = \"events[0].mas\"\nuniform = [1.0, 2.0]",
            "the scene has no key `mas` there",
        ),
        (
            "key = \"base.type\"\nuniform = [1.0, 2.0]",
            "names a string, not a number",
        ),
        (
            "key = \"events[0]..x\"\nuniform = [1.0, 2.0]",
            "expected a TOML path like",
        ),
        ("key = \"events[0].mass\"\nuniform = [2.0, 1.0]", "lo < hi"),
        (
            "key = \"events[0].mass\"\nnormal = { mean = 1.0, std = 0.0 }",
            "std finite and > 0",
        ),
        (
            "key = \"events[0].mass\"\nuniform = [1.0, 2.0]\nvalues = [1.0]",
            "exactly one of",
        ),
        (
            "key = \"simulation.output_every\"\nuniform = [1.0, 2.0]",
            "sweep it by `values` of integers",
        ),
        (
            "key = \"events[0].mass\"\nuniform = [1.0, 2.0]\nextra = 1",
            "unknown field `extra`",
        ),
    ];
    for (param, want) in cases {
        let f = sweep_file(&d, &format!("[[parameter]]\n{param}\n"));
        let e = cli(&["sweep", &f]).unwrap_err();
        assert!(e.contains("sweep.toml") && e.contains(want), "{param}: {e}");
    }
    let f = sweep_file(
        &d,
        "runs = 3\n[[parameter]]\nkey = \"drives.kp\"\nvalues = [1.0, 2.0]\n",
    );
    let e = cli(&["sweep", &f]).unwrap_err();
    assert!(
        e.contains("runs (line 2)") && e.contains("needs a `uniform` or `normal`"),
        "{e}"
    );
    let e = cli(&["sweep", &example(), "--shard", "4/4"]).unwrap_err();
    assert!(
        e.contains("--shard") && e.contains("0 <= INDEX < COUNT"),
        "{e}"
    );
}
