//! Reliability: what the binary promises about its outputs, tested on the binary.
//!
//! - a closed pipe ends quietly with exit 0; a full disk (`/dev/full`) is a clean error;
//! - an output path that is a directory, under a file, or an input is refused before any work,
//!   and an existing output is replaced only with `--force`;
//! - Ctrl-C during `simulate` leaves a valid, truncated CSV and a summary marked incomplete;
//! - bad `bench` arguments are usage errors; user errors print no backtrace unless asked;
//! - names with bidirectional-override characters generate code without them in doc comments
//!   and escaped in string literals;
//! - `generate` and `count` stay within measured memory and time (peak resident memory of the
//!   child, from `getrusage`).

mod precondition;

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn kanegen() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_kanegen"));
    c.current_dir(root());
    c
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("kanegen-rel-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

const SSRMS: &str = "tests/data/reference/ssrms_nguyen_hughes_1994.urdf";

/// A states file of `n` random-looking SSRMS states (7 joints).
fn many_states(n: usize) -> String {
    let states: Vec<String> = (0..n)
        .map(|k| {
            let q: Vec<String> = (0..7)
                .map(|i| format!("{}", ((k * 7 + i) as f64).sin()))
                .collect();
            format!(r#"{{"q":[{0}],"qd":[{0}]}}"#, q.join(","))
        })
        .collect();
    format!(r#"{{"states":[{}]}}"#, states.join(","))
}

#[test]
fn broken_pipe_ends_quietly_with_exit_0() {
    let d = tmp("pipe");
    let states = d.join("states.json");
    std::fs::write(&states, many_states(3000)).unwrap();
    let mut child = kanegen()
        .args(["eval", SSRMS, "--states"])
        .arg(&states)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Read a little, then close the pipe (what `| head -2` does).
    let mut first = [0u8; 64];
    child
        .stdout
        .as_mut()
        .unwrap()
        .read_exact(&mut first)
        .unwrap();
    drop(child.stdout.take());
    let mut err = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    let status = child.wait().unwrap();
    assert!(status.success(), "exit {status:?}, stderr: {err}");
    assert!(err.is_empty(), "stderr: {err}");
}

#[test]
fn full_disk_is_a_clean_error() {
    let Ok(full) = std::fs::OpenOptions::new().write(true).open("/dev/full") else {
        precondition::absent("dev_full", "no /dev/full on this system");
        return;
    };
    let o = kanegen()
        .args(["generate", SSRMS])
        .stdout(full)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.starts_with("Error: ") && err.contains("No space left"),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
}

/// Each bad output path is refused before any work: a simulation of 1e5 s would take an hour,
/// the refusal takes well under a second.
#[test]
fn bad_output_paths_are_refused_before_any_work() {
    let d = tmp("paths");
    let file = d.join("a_file");
    std::fs::write(&file, "x").unwrap();
    let scene = "tests/data/reliability/long.toml";
    let cases: Vec<(Vec<String>, &str)> = vec![
        (
            vec![
                "simulate".into(),
                scene.into(),
                "--out".into(),
                file.display().to_string(),
            ],
            "not a directory",
        ),
        (
            vec![
                "simulate".into(),
                scene.into(),
                "--out".into(),
                file.join("sub").display().to_string(),
            ],
            "cannot create",
        ),
        (
            vec![
                "generate".into(),
                SSRMS.into(),
                "-o".into(),
                file.join("x.rs").display().to_string(),
            ],
            "not a directory",
        ),
        (
            vec![
                "generate".into(),
                SSRMS.into(),
                "-o".into(),
                d.display().to_string(),
            ],
            "is a directory",
        ),
        (
            vec![
                "generate".into(),
                SSRMS.into(),
                "-o".into(),
                file.display().to_string(),
            ],
            "--force",
        ),
        (
            vec!["table1".into(), "--out".into(), file.display().to_string()],
            "not a directory",
        ),
    ];
    for (args, want) in cases {
        let t0 = Instant::now();
        let o = kanegen().args(&args).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains(want), "{args:?}: {err}");
        assert!(
            t0.elapsed() < Duration::from_secs(5),
            "{args:?} did work first"
        );
    }
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "x", "untouched");
}

#[test]
fn generate_never_writes_over_its_input_and_replaces_only_with_force() {
    let d = tmp("self");
    let model = d.join("arm.toml");
    std::fs::copy(root().join("models/two_link.toml"), &model).unwrap();
    let before = std::fs::read_to_string(&model).unwrap();
    for force in [false, true] {
        let mut c = kanegen();
        c.arg("generate").arg(&model).arg("-o").arg(&model);
        if force {
            c.arg("--force");
        }
        let o = c.output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && err.contains("is the input"), "{err}");
    }
    assert_eq!(std::fs::read_to_string(&model).unwrap(), before);
    // Through another spelling of the same path, too.
    let other = d.join(".").join("arm.toml");
    let o = kanegen()
        .arg("generate")
        .arg(&model)
        .arg("-o")
        .arg(&other)
        .arg("--force")
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert_eq!(std::fs::read_to_string(&model).unwrap(), before);
    // A new file is written whole; an existing one only with --force.
    let out = d.join("arm.rs");
    let gen = |force: bool| {
        let mut c = kanegen();
        c.arg("generate").arg(&model).arg("-o").arg(&out);
        if force {
            c.arg("--force");
        }
        c.output().unwrap()
    };
    assert!(gen(false).status.success());
    let first = std::fs::read_to_string(&out).unwrap();
    assert!(first.contains("pub fn mass_matrix"));
    let o = gen(false);
    assert!(String::from_utf8_lossy(&o.stderr).contains("--force"));
    assert!(gen(true).status.success());
    assert_eq!(std::fs::read_to_string(&out).unwrap(), first);
    // No temporary file is left behind.
    let names: Vec<String> = std::fs::read_dir(&d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(names.iter().all(|n| !n.starts_with('.')), "{names:?}");
}

#[test]
fn interrupted_simulation_keeps_a_valid_partial_csv_and_an_incomplete_summary() {
    let d = tmp("sigint");
    let out = d.join("run");
    let child = kanegen()
        .args([
            "simulate",
            "tests/data/reliability/long.toml",
            "--json",
            "--out",
        ])
        .arg(&out)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Interrupt once the run has streamed some rows (a fixed sleep loses on a loaded machine).
    // The CSV streams into `.trajectory.csv-*.partial` (buffered) until it is renamed.
    let streamed = || {
        std::fs::read_dir(&out).map_or(0, |rd| {
            rd.filter_map(Result::ok)
                .filter(|e| {
                    e.file_name()
                        .to_string_lossy()
                        .starts_with(".trajectory.csv-")
                })
                .map(|e| e.metadata().map_or(0, |m| m.len()))
                .sum::<u64>()
        })
    };
    let started = std::time::Instant::now();
    while streamed() == 0 {
        assert!(
            started.elapsed() < Duration::from_secs(120),
            "no rows streamed in 120 s"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    let killed = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(130), "{err}");
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["complete"], false);
    assert_eq!(summary["stopped"], "interrupted");
    let t_end = summary["t_end"].as_f64().unwrap();
    assert!(t_end > 0.0 && t_end < 1e5, "{t_end}");
    let stdout: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(stdout["complete"], false);
    let csv = std::fs::read_to_string(out.join("trajectory.csv")).unwrap();
    let mut lines = csv.lines();
    let width = lines.next().unwrap().split(',').count();
    assert_eq!(width, 13);
    let mut last_t = -1.0;
    let mut rows = 0;
    for l in lines {
        let cells: Vec<f64> = l.split(',').map(|c| c.parse().unwrap()).collect();
        assert_eq!(cells.len(), width, "{l}");
        assert!(cells.iter().all(|c| c.is_finite()));
        assert!(cells[0] > last_t);
        last_t = cells[0];
        rows += 1;
    }
    assert!(rows > 10, "{rows} rows");
    assert_eq!(last_t, t_end, "the CSV ends at the state reached");
    assert!(csv.ends_with('\n'));
    assert!(out.join("joints.svg").exists());
}

#[test]
fn bench_arguments_are_validated() {
    for args in [
        ["--rounds", "0"],
        ["--calls", "0"],
        ["--rounds", "99999999999"],
        ["--batch", "0"],
    ] {
        let o = kanegen().arg("bench").args(args).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
}

#[test]
fn user_errors_have_no_backtrace_unless_asked() {
    let o = kanegen()
        .args(["eval", "nowhere.toml", "--states", "nowhere.json"])
        .env("RUST_BACKTRACE", "1")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1));
    assert!(err.starts_with("Error: model `nowhere.toml`"), "{err}");
    assert!(
        !err.contains("backtrace") && err.lines().count() == 1,
        "{err}"
    );
    let o = kanegen()
        .args(["-v", "eval", "nowhere.toml", "--states", "nowhere.json"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("Caused by") && err.contains("backtrace"),
        "{err}"
    );
}

/// Names with U+202E, U+2066/7 and BEL: no such character anywhere in the generated file (doc
/// comments drop them, string literals escape them), and the file compiles (`tests/macro.rs`
/// compiles the same model through `dynamics!`).
#[test]
fn bidirectional_names_are_escaped_in_generated_code() {
    let o = kanegen()
        .args(["generate", "tests/data/reliability/bidi_names.toml"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let code = String::from_utf8(o.stdout).unwrap();
    let bad = |c: char| {
        c.is_control() && c != '\n'
            || matches!(c as u32, 0x200E | 0x200F | 0x202A..=0x202E | 0x2066..=0x2069)
    };
    assert!(
        !code.chars().any(bad),
        "raw control or bidi character in the code"
    );
    assert!(
        code.contains(r"shoulder\u{202e}\u{2066}evil\u{7}"),
        "escaped in JOINTS"
    );
    assert!(code.contains(r"tool\u{202e}\u{2067}"), "escaped in FRAMES");
}

/// Peak resident memory (MB) and wall time of a `kanegen` run.
#[cfg(target_os = "linux")]
fn measure(args: &[&str]) -> (f64, f64) {
    let t0 = Instant::now();
    let o = kanegen().args(args).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let secs = t0.elapsed().as_secs_f64();
    // SAFETY: getrusage fills the struct it is given.
    let mut ru: libc::rusage = unsafe { std::mem::zeroed() };
    unsafe { libc::getrusage(libc::RUSAGE_CHILDREN, &mut ru) };
    // ru_maxrss (KB) is the largest child so far: run the measured command before any larger one.
    (ru.ru_maxrss as f64 / 1024.0, secs)
}

/// `generate` on a 200-joint chain of general geometry stays under 1 GB of peak memory
/// (measured 0.40 GB and 10 s, compact code; `docs/limits.md`, "Memory and time of `generate`
/// and `count`").
#[cfg(target_os = "linux")]
#[test]
fn generate_at_n_200_stays_under_1_gb() {
    let d = tmp("mem");
    let model = d.join("chain200.toml");
    let chain = kanegen::model::random::random_chain(
        &kanegen::model::random::ChainSpec {
            n: 200,
            ..Default::default()
        },
        200,
    );
    std::fs::write(&model, kanegen::model::io::to_toml(&chain)).unwrap();
    let out = d.join("chain200.rs");
    let (mb, secs) = measure(&[
        "generate",
        model.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    println!("generate N = 200: {mb:.0} MB peak, {secs:.1} s");
    assert!(mb < 1024.0, "{mb:.0} MB");
    let code = std::fs::read_to_string(&out).unwrap();
    assert!(
        code.contains("pub fn forward_dynamics(") && code.contains("[::core::primitive::f64; 200]")
    );
    std::fs::remove_dir_all(&d).ok();
}

/// Errors blame the right thing: the scene key and the bound or limit, the lock, the state.
#[test]
fn messages_name_what_is_wrong() {
    use kanegen::sim::scene::{Scene, SceneOptions};
    let scene = |sim: &str| format!("model = \"models/two_link.toml\"\n[simulation]\n{sim}\n");
    let err = |text: &str| match Scene::parse(text, root()) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => format!("{e:#}"),
    };
    let e = err(&scene(
        "duration = 1.0\nintegrator = \"dopri5\"\ntolerance = 1e-300",
    ));
    assert!(
        e.contains("simulation.tolerance") && e.contains("1e-14") && e.contains("round"),
        "{e}"
    );
    let e = err(&scene("duration = 1.0\nstep = 1e-300"));
    assert!(
        e.contains("simulation.step") && e.contains("allow_long"),
        "{e}"
    );
    let e = err(&scene("duration = 1e300"));
    assert!(e.contains("exceeds the limit 1e8"), "{e}");
    // Allowed when asked for (not run here).
    let long = scene("duration = 1e7\nstep = 0.01");
    assert!(Scene::parse(&long, root()).is_err());
    assert!(Scene::parse_with(&long, root(), SceneOptions { allow_long: true }).is_ok());
    let e = err("model = \"models/two_link.toml\"\n[effects]\ngravity = [0.0, 0.0, 1e308]\n[simulation]\nduration = 1.0\n");
    assert!(
        e.contains("effects.gravity") && e.contains("1e3 m/s²"),
        "{e}"
    );
    let e = err("model = \"models/two_link.toml\"\n[initial]\nqd = [1e160, 0.0]\n[simulation]\nduration = 1.0\n");
    assert!(e.contains("initial.qd") && e.contains("1e6"), "{e}");

    let mut out = Vec::new();
    let e = kanegen::cli::app::run_args(
        [
            "kanegen",
            "generate",
            "models/two_link.toml",
            "--lock",
            "0=nan",
        ]
        .map(|a| {
            if a.starts_with("models/") {
                root().join(a).display().to_string()
            } else {
                a.to_string()
            }
        }),
        &mut out,
    )
    .unwrap_err();
    let e = format!("{e:#}");
    assert!(
        e.contains("--lock `0=nan`") && e.contains("lock value") && !e.contains("origin"),
        "{e}"
    );
}

/// `generate` refuses more than 1000 joints before any work, naming the flag that allows it.
#[test]
fn generate_refuses_more_than_1000_joints_without_allow_large() {
    let d = tmp("large");
    let model = d.join("chain1001.toml");
    let chain = kanegen::model::random::random_chain(
        &kanegen::model::random::ChainSpec {
            n: 1001,
            ..Default::default()
        },
        1001,
    );
    std::fs::write(&model, kanegen::model::io::to_toml(&chain)).unwrap();
    let t = Instant::now();
    let o = kanegen()
        .args(["generate", model.to_str().unwrap()])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("1001 joints") && err.contains("--allow-large"),
        "{err}"
    );
    assert!(o.stdout.is_empty());
    assert!(t.elapsed().as_secs_f64() < 30.0, "refused before tracing");
    std::fs::remove_dir_all(&d).ok();
}
