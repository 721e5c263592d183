//! Ingest of a real ROS 2 bag written by the standard tooling (MichaelGrupp/evo
//! test data, GPL-3.0; a simulated TurtleBot, but a real third-party file).

use mmtrack_io::recording::PoseStream;
use mmtrack_io::{RecordingEvent, RecordingReader};

use super::common::{mmtrack, text};

/// Absolute trajectory error of `<tables>/poses` against
/// `<tables>/ground_truth` (sequence nav2_turtlebot): prints the poses
/// scored, the RMSE and the largest error, metres.
const ATE_PY: &str = r#"
import sys
import numpy as np
import pyarrow.parquet as pq
part = lambda t: f"{sys.argv[1]}/{t}/sequence=nav2_turtlebot/part-0.parquet"
e = pq.read_table(part("poses")).to_pydict()
g = pq.read_table(part("ground_truth")).to_pydict()
t, gt = np.array(e["t_ns"]), np.array(g["t_ns"])
inside = (t >= gt[0]) & (t <= gt[-1])
p = np.c_[np.array(e["x_m"])[inside], np.array(e["y_m"])[inside]]
q = np.c_[np.interp(t[inside], gt, g["x_m"]), np.interp(t[inside], gt, g["y_m"])]
u, _, vt = np.linalg.svd((p - p.mean(0)).T @ (q - q.mean(0)))
r = vt.T @ np.diag([1.0, np.sign(np.linalg.det(vt.T @ u.T))]) @ u.T
err = np.linalg.norm((p - p.mean(0)) @ r.T + q.mean(0) - q, axis=1)
print(len(p), np.sqrt(np.mean(err**2)), err.max())
"#;

#[test]
fn ros2_bag_odom_becomes_poses() {
    let Some(realdata) = super::common::realdata("ros2_bag") else { return };
    let bag = realdata.join("ros2-mcap/nav2_turtlebot.mcap");
    let dir = tempfile::tempdir().unwrap();
    let out = mmtrack(dir.path(), &["ingest", "ros2", bag.to_str().unwrap(), "-o", "bag.mcap"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    // `mmtrack inspect` of the bag counts 2639 messages on /odom.
    assert!(stdout.contains("2639 poses"), "{stdout}");
    let poses: Vec<_> = RecordingReader::open(&dir.path().join("bag.mcap"))
        .unwrap()
        .filter_map(|e| match e.unwrap() {
            RecordingEvent::Pose { stream: PoseStream::Estimate, pose } => Some(pose),
            _ => None,
        })
        .collect();
    assert_eq!(poses.len(), 2639);
    assert!(poses.windows(2).all(|w| w[1].t_ns > w[0].t_ns));
    // A TurtleBot in a small simulated world: positions within tens of metres.
    assert!(poses.iter().all(|p| p.parent_from_child.translation_norm_m() < 50.0));
    // Stamped with the simulator's clock: `inspect` says so instead of a
    // date in 1970 (before: "from 1970-01-01 00:15:28 UTC").
    let out = mmtrack(dir.path(), &["inspect", "bag.mcap"]);
    let span = text(&out).0.lines().find(|l| l.contains("time span")).map(str::to_string).unwrap_or_default();
    assert!(span.contains("time_base = sim_time: not a date") && !span.contains("1970"), "{span}");

    // /amcl_pose is a PoseWithCovarianceStamped topic.
    let out = mmtrack(
        dir.path(),
        &["ingest", "ros2", bag.to_str().unwrap(), "-o", "amcl.mcap", "--pose-topic", "/amcl_pose"],
    );
    assert!(text(&out).0.contains("135 poses"), "{}", text(&out).1);

    // /odom as a table for pandas / DuckDB (`process poses`); with no ground
    // truth in the recording, analyze says what it lacks.
    let out = mmtrack(dir.path(), &["process", "poses", "bag.mcap", "-o", "tables"]);
    assert!(text(&out).0.contains("poses: estimate 2639 (96.7 s, 34.3 m), ground truth 0 (none)"), "{}", text(&out).1);
    let table = dir.path().join("tables/poses/sequence=nav2_turtlebot/part-0.parquet");
    let rows: Vec<mmtrack_core::StampedPose> = mmtrack_io::table::read_table(&table).unwrap();
    assert_eq!(rows, poses);
    assert!(!dir.path().join("tables/ground_truth").exists());
    let out = mmtrack(dir.path(), &["analyze", "tables", "-o", "analysis"]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = text(&out).1;
    assert!(stderr.contains("sequence nav2_turtlebot has the poses table but no ground_truth table"), "{stderr}");

    // /amcl_pose as the reference in the same recording: /odom is then scored against it.
    let bag_arg = bag.to_str().unwrap();
    let out = mmtrack(dir.path(), &["ingest", "ros2", bag_arg, "-o", "gt.mcap", "--ground-truth-topic", "/amcl_pose"]);
    assert!(text(&out).0.contains("2639 poses, 135 ground-truth poses"), "{}", text(&out).1);
    let out = mmtrack(dir.path(), &["process", "poses", "gt.mcap", "-o", "scored", "-q"]);
    assert!(out.status.success(), "{}", text(&out).1);
    let out = mmtrack(dir.path(), &["analyze", "scored", "-o", "scored-an", "--segment-lengths-m", "1,2,4,8", "-q"]);
    assert!(out.status.success(), "{}", text(&out).1);
    let metrics: Vec<mmtrack_io::table::TrajectoryMetrics> = mmtrack_io::table::read_table(
        &dir.path().join("scored-an/tables/trajectory_metrics/sequence=nav2_turtlebot/part-0.parquet"),
    )
    .unwrap();
    // /odom's poses outside /amcl_pose's time span are not scored; the rest are.
    assert_eq!((metrics[0].estimate_poses, metrics[0].associated_poses), (2639, 2578));
    // The ATE, computed independently from the two tables with numpy: the
    // ground truth interpolated at the estimate's times inside its span, the
    // least-squares rotation and translation (Kabsch), the position RMSE.
    let python = super::common::venv_python().expect("Python 3 with pip access to PyPI (numpy, pyarrow) is needed");
    let script = dir.path().join("ate.py");
    std::fs::write(&script, ATE_PY).unwrap();
    let out = std::process::Command::new(python).arg(&script).arg(dir.path().join("scored")).output().unwrap();
    assert!(out.status.success(), "{}", text(&out).1);
    let numpy: Vec<f64> = text(&out).0.split_whitespace().map(|v| v.parse().unwrap()).collect();
    assert_eq!(numpy[0] as u64, metrics[0].associated_poses);
    assert!((numpy[1] - metrics[0].ate_rmse_m).abs() < 1e-9, "numpy {numpy:?} vs {:?}", metrics[0]);
    assert!((numpy[2] - metrics[0].ate_max_m).abs() < 1e-9, "numpy {numpy:?} vs {:?}", metrics[0]);
    assert!(metrics[0].ate_rmse_m > 0.1, "/odom drifts from /amcl_pose: {:?}", metrics[0]);
    for (args, message) in [
        (&["--ground-truth-topic", "/odom"][..], "--ground-truth-topic /odom is also --pose-topic"),
        (&["--ground-truth-topic", "/amcl_pose", "--poses-are-ground-truth"][..], "one ground truth per recording"),
    ] {
        let out = mmtrack(dir.path(), &[&["ingest", "ros2", bag_arg, "-o", "bad.mcap"][..], args].concat());
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        assert!(text(&out).1.contains(message), "{}", text(&out).1);
    }

    // A topic the bag lacks is one clear error listing what it has.
    let out = mmtrack(dir.path(), &["ingest", "ros2", bag.to_str().unwrap(), "-o", "x.mcap", "--gnss-topic", "/fix"]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr.contains("no topic /fix") && stderr.contains("/odom"), "{stderr}");
    assert!(!dir.path().join("x.mcap").exists());
}

#[test]
fn ros2_topic_of_the_wrong_type_is_an_error_for_every_option() {
    let Some(realdata) = super::common::realdata("ros2_wrong_type") else { return };
    let bag = realdata.join("ros2-mcap/nav2_turtlebot.mcap");
    let dir = tempfile::tempdir().unwrap();
    let bag = bag.to_str().unwrap();
    let radar = ["--radar-topic", "/odom", "--radar-range-resolution-m", "0.0438", "--pose-topic", "none"];
    for (args, topic, found, expected) in [
        (&radar[..], "/odom", "nav_msgs/msg/Odometry", "sensor_msgs/msg/Image"),
        // With the default --pose-topic /odom beside it, the radar option is still checked.
        (&radar[..4], "/odom", "nav_msgs/msg/Odometry", "sensor_msgs/msg/Image"),
        (
            &["--gnss-topic", "/amcl_pose"][..],
            "/amcl_pose",
            "geometry_msgs/msg/PoseWithCovarianceStamped",
            "sensor_msgs/msg/NavSatFix",
        ),
        (
            &["--pose-topic", "/tf"][..],
            "/tf",
            "tf2_msgs/msg/TFMessage",
            "nav_msgs/msg/Odometry or geometry_msgs/msg/PoseWithCovarianceStamped",
        ),
    ] {
        let out = mmtrack(dir.path(), &[&["ingest", "ros2", bag, "-o", "x.mcap"][..], args].concat());
        let (stdout, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {stdout}");
        assert!(stderr.contains(&format!("topic {topic} has type {found}; expected {expected}")), "{args:?}: {stderr}");
        // One line, the bag named once.
        assert_eq!((stderr.trim().lines().count(), stderr.matches("nav2_turtlebot.mcap").count()), (1, 1), "{stderr}");
        assert!(!dir.path().join("x.mcap").exists());
    }
}
