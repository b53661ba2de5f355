//! The room's cost (issue 28, the world's cost per robot second): a crowd
//! of 10,000 obstacles away from the robot changes nothing it feels, and
//! costs no test of a point against any of them; a robot standing still
//! is not felt again.

mod rom_support;

use std::fmt::Write as _;

use cards::Room;
use rom_support::{Session, build, examples_dir};

/// The room of tests/tests/room.rs, its walls wide enough for the posts
/// (the world file refuses obstacles beyond the walls): a post 20 cm round
/// in front of the robot, which stands at (100, 100) facing east.
const ROOM: &str = r#"
walls = [[0, -500], [1500, -500], [1500, 700], [0, 700]]

[[obstacle]]
circle = { x = 160, y = 100, radius = 20 }

[robot]
x = 100
y = 100
heading = 0
"#;

/// `count` posts 2 cm round, 10 cm apart, in rows of 100 from (400,
/// -400): far east of [`ROOM`]'s robot, where patrol does not take it.
fn posts(count: usize) -> String {
    let mut text = String::new();
    for index in 0..count {
        let (column, row) = (index % 100, index / 100);
        write!(
            text,
            "[[obstacle]]\ncircle = {{ x = {}, y = {}, radius = 1 }}\n",
            400 + 10 * column,
            10 * row as i64 - 400
        )
        .expect("writing to a String");
    }
    text
}

/// [`ROOM`] with `count` [`posts`] far from its robot.
fn crowded(count: usize) -> String {
    ROOM.replace("[robot]", &format!("{}\n[robot]", posts(count)))
}

/// Patrol's first four seconds in `world`: the trail (poses and bumps,
/// their bits) and the obstacle tests the room made.
fn patrol_in(world: &str) -> (String, u64) {
    let room = Room::load("room.toml", world).expect("the world file loads");
    let view = room.view();
    let mut s = Session::new();
    s.robot.set_surroundings(Box::new(room));
    let patrol = build(&[examples_dir().join("patrol/patrol.s")], "scorpion-os");
    s.robot.load_image(&patrol).expect("patrol loads");
    s.send("/2A1");
    s.robot.run_until(4_000_000).expect("runs");
    let trail = view.trail();
    let mut bits = String::new();
    for (at, pose) in &trail.poses {
        writeln!(
            bits,
            "{at} {:016x} {:016x} {:016x}",
            pose.at.x.to_bits(),
            pose.at.y.to_bits(),
            pose.heading.to_bits()
        )
        .expect("writing to a String");
    }
    writeln!(bits, "bumps {:?}", trail.bumps).expect("writing to a String");
    (bits, view.obstacle_tests())
}

#[test]
fn a_crowd_far_away_changes_nothing_and_costs_no_test() {
    let (alone, tests_alone) = patrol_in(ROOM);
    let world = crowded(10_000);
    assert_eq!(world.matches("[[obstacle]]").count(), 10_001);
    let (crowd, tests_crowd) = patrol_in(&world);
    assert!(
        alone.contains("bumps [("),
        "the robot met the post: {alone}"
    );
    assert!(alone == crowd, "the same path, bit for bit");
    assert!(tests_alone > 0, "the post was tested");
    // Testing every obstacle, the crowd would cost 10,001 tests a point
    // instead of one. Tested only where they lie, the far posts cost
    // none: what is left is the post, met at a few more or fewer points
    // as the grid's cells are smaller or larger with the crowd.
    assert!(
        tests_crowd <= 2 * tests_alone,
        "the far posts cost tests: {tests_crowd} against {tests_alone} alone"
    );
}

#[test]
fn a_robot_standing_still_is_not_felt_again() {
    // No walls: the robot stands among the posts, 3 cm round to stand
    // clear of them (a start touching one is refused).
    let world = format!(
        "{}\n[robot]\nx = 455\ny = -385\nheading = 0\nradius = 3\n",
        posts(10_000)
    );
    let room = Room::load("room.toml", &world).expect("the world file loads");
    let view = room.view();
    let mut s = Session::new();
    s.robot.set_surroundings(Box::new(room));
    s.robot.run_for(10_000).expect("runs");
    let first = view.obstacle_tests();
    assert!(first > 0, "the bumpers were felt at the start pose");
    assert!(
        first < 1_000,
        "only the posts near the robot were tested: {first}"
    );
    // A second of robot time, a look at the motors every millisecond.
    s.robot.run_for(1_000_000).expect("runs");
    assert_eq!(view.obstacle_tests(), first, "nothing moved, nothing felt");
}
