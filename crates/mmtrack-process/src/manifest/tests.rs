use super::*;

fn manifest(text: &str) -> anyhow::Result<Manifest> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.toml");
    std::fs::write(&path, text).unwrap();
    read_manifest(&path)
}

fn refusal(text: &str) -> String {
    manifest(text).err().map(|e| format!("{e:#}")).unwrap_or_else(|| panic!("accepted: {text}"))
}

#[test]
fn process_tasks_get_the_output_and_lines_are_quoted() {
    let m = manifest("[[task]]\nargs = [\"odometry\", \"a b.mcap\", \"--preset\", \"cfear\"]\n").unwrap();
    let line = m.tasks[0].command_line("t", true);
    assert_eq!(line, ["process", "odometry", "a b.mcap", "--preset", "cfear", "-o", "t", "--force"]);
    assert_eq!(shell_word("a b.mcap"), "'a b.mcap'");
    assert_eq!(m.tasks[0].step, Step::Process);
    assert_eq!(m.levels(), vec![vec![0]]);
}

#[test]
fn steps_with_needs_run_in_levels_and_name_their_outputs() {
    let m = manifest(
        "[[task]]\nstep = \"analyze\"\nneeds = [\"odo\", \"mpc\"]\nargs = [\"{tables}\", \"-o\", \"analysis\"]\n\
         [[task]]\nname = \"ingest\"\nstep = \"ingest\"\nargs = [\"oxford\", \"data/a\", \"-o\", \"rec/a.mcap\"]\n\
         [[task]]\nname = \"odo\"\nneeds = [\"ingest\"]\nargs = [\"odometry\", \"rec/a.mcap\", \"--threads\", \"3\"]\n\
         [[task]]\nname = \"mpc\"\nargs = [\"mpc\", \"s.mcap\"]\n\
         [[task]]\nname = \"spebt\"\nneeds = [\"odo\"]\nargs = [\"beam\", \"--tracker\", \"spebt\", \"rec/a.mcap\"]\n",
    )
    .unwrap();
    // ingest and mpc need nothing; odometry needs the ingest; the analysis
    // and SPEBT (a process step needing a process step) need the odometry.
    assert_eq!(m.levels(), vec![vec![1, 3], vec![2], vec![0, 4]]);
    assert_eq!(m.tasks[0].needs, [2, 3]);
    assert_eq!(m.tasks[0].command_line("t", false), ["analyze", "t", "-o", "analysis"]);
    assert_eq!(m.tasks[0].own_output("t").as_deref(), Some("analysis"));
    assert_eq!(m.tasks[1].command_line("t", false), ["ingest", "oxford", "data/a", "-o", "rec/a.mcap"]);
    assert_eq!((m.tasks[2].threads(), m.tasks[3].threads()), (Some(3), None));
    assert_eq!(m.tasks[2].label(), "task 2 (odo)");
    let lines = task_lines(&m, "t");
    let first: serde_json::Value = serde_json::from_str(&lines[2]).unwrap();
    assert_eq!(first["level"], 1);
    assert_eq!(first["threads"], 3);
    assert_eq!(first["needs"], serde_json::json!([1]));
    assert_eq!(first["command"][0], "process");
}

#[test]
fn failed_needs_stop_their_dependents_only() {
    let m = manifest(
        "[[task]]\nname = \"a\"\nargs = [\"mpc\", \"a.mcap\"]\n\
         [[task]]\nneeds = [\"a\"]\nargs = [\"mpc\", \"b.mcap\"]\n\
         [[task]]\nargs = [\"mpc\", \"c.mcap\"]\n",
    )
    .unwrap();
    let outcomes = run_levels(&m, |t| if t.index == 0 { anyhow::bail!("broken") } else { Ok(t.index == 2) });
    assert!(matches!(outcomes[0], Outcome::Failed(_)), "{outcomes:?}");
    assert!(matches!(outcomes[1], Outcome::NotRun(0)), "{outcomes:?}");
    assert!(matches!(outcomes[2], Outcome::Done), "{outcomes:?}");
}

#[test]
fn bad_manifests_are_refused_naming_file_task_and_key() {
    let ok = "[[task]]\nname = \"a\"\nargs = [\"mpc\", \"a.mcap\"]\n";
    for (text, message) in [
        ("task = []\n", "m.toml: no [[task]] entries"),
        ("title = \"x\"\n[[task]]\nargs = [\"mpc\"]\n", "m.toml: unknown key `title`"),
        ("[[task]]\nargs = []\n", "m.toml: task 0: key `args`: empty"),
        (
            "[[task]]\nargz = [\"mpc\"]\n",
            "m.toml: task 0: unknown key `argz` (expected one of name, step, needs, args)",
        ),
        (&format!("{ok}[[task]]\nnedds = [\"a\"]\nargs = [\"mpc\"]\n"), "m.toml: task 1: unknown key `nedds`"),
        (
            "[[task]]\nstep = \"export\"\nargs = [\"x\"]\n",
            "m.toml: task 0: key `step`: \"export\", expected \"ingest\", \"process\" or \"analyze\"",
        ),
        (
            "[[task]]\nargs = [\"mpc\", \"x.mcap\", \"-o\", \"y\"]\n",
            "m.toml: task 0: key `args`: leave -o/--output out",
        ),
        ("[[task]]\nargs = [\"manifest\", \"m.toml\"]\n", "key `args`: a manifest cannot run a manifest"),
        (
            "[[task]]\nstep = \"ingest\"\nargs = [\"oxford\", \"d\"]\n",
            "task 0: key `args`: an ingest task names its output",
        ),
        (
            "[[task]]\nargs = [\"mpc\", \"--threads\", \"100000\"]\n",
            "task 0: key `args`: --threads 100000: expected at most 1024",
        ),
        ("[[task]]\nargs = [\"mpc\", \"--threads\", \"many\"]\n", "task 0: key `args`: --threads 'many'"),
        (&format!("{ok}{ok}"), "m.toml: task 1: key `name`: 'a' is already task 0's"),
        ("[[task]]\nname = \"7\"\nargs = [\"mpc\"]\n", "task 0: key `name`: '7'"),
        ("[[task]]\nneeds = [\"z\"]\nargs = [\"mpc\"]\n", "m.toml: task 0: key `needs`: no task is named 'z'"),
        (
            "[[task]]\nname = \"a\"\nneeds = [\"a\"]\nargs = [\"mpc\"]\n",
            "task 0 (a): key `needs`: a task cannot need itself",
        ),
        (
            "[[task]]\nname = \"an\"\nstep = \"analyze\"\nargs = [\"t\", \"-o\", \"x\"]\n\
             [[task]]\nstep = \"ingest\"\nneeds = [\"an\"]\nargs = [\"oxford\", \"d\", \"-o\", \"r.mcap\"]\n",
            "m.toml: task 1: key `needs`: task 0 (an) is a later step (analyze)",
        ),
        (
            "[[task]]\nname = \"a\"\nneeds = [\"c\"]\nargs = [\"mpc\"]\n[[task]]\nname = \"b\"\nneeds = [\"a\"]\nargs = [\"mpc\"]\n\
             [[task]]\nname = \"c\"\nneeds = [\"b\"]\nargs = [\"mpc\"]\n",
            "m.toml: task 0 (a): key `needs`: a cycle: task 0 (a) -> task 2 (c) -> task 1 (b) -> task 0 (a)",
        ),
        // A key of the wrong type is named (serde's message named none).
        (
            "[[task]]\nargs = \"odometry x\"\n",
            "m.toml: task 0: key `args`: \"odometry x\", expected an array of strings",
        ),
        ("[[task]]\nstep = \"simulate\"\nargs = [\"x\"]\n", "task 0: key `step`: \"simulate\", expected \"ingest\""),
        ("[[task]]\nname = 3\nargs = [\"x\"]\n", "task 0: key `name`: 3, expected a string"),
    ] {
        let err = refusal(text);
        assert!(err.contains(message), "{text}\n{err}");
    }
    let many = "[[task]]\nargs = [\"mpc\"]\n".repeat(MAX_TASKS + 1);
    assert!(refusal(&many).contains("m.toml: key `task`: 100001 tasks; expected at most 100000"));
    let long = format!("[[task]]\nargs = [{}]\n", vec!["\"x\""; MAX_WORDS + 1].join(","));
    assert!(refusal(&long).contains("task 0: key `args`: 1001 words; expected at most 1000"));
    // A cycle through 1000 tasks is named in one short line (100 000 printed 2.3 MB).
    let ring: String = (0..1000)
        .map(|i| format!("[[task]]\nname = \"t{i}\"\nneeds = [\"t{}\"]\nargs = [\"mpc\"]\n", (i + 1) % 1000))
        .collect();
    let err = refusal(&ring);
    assert!(err.contains("-> ... (1000 tasks in all) -> task 0 (t0)") && err.len() < 400, "{err}");
}

#[test]
fn a_chain_of_the_most_tasks_is_levelled_in_linear_time() {
    // Task i needs task i + 1: the last task is level 0, the first the deepest.
    let tasks: Vec<Task> = (0..MAX_TASKS)
        .map(|i| Task {
            index: i,
            name: None,
            step: Step::Process,
            needs: if i + 1 < MAX_TASKS { vec![i + 1] } else { Vec::new() },
            args: vec!["mpc".into()],
        })
        .collect();
    let started = std::time::Instant::now();
    let levels = Manifest { tasks }.levels();
    assert_eq!(levels.len(), MAX_TASKS);
    assert_eq!((levels[0].as_slice(), levels[MAX_TASKS - 1].as_slice()), (&[MAX_TASKS - 1][..], &[0][..]));
    // Linear in tasks + needs (relaxing level by level would be quadratic here).
    assert!(started.elapsed() < std::time::Duration::from_secs(5), "{:?}", started.elapsed());
}
