//! The robot in a room (issue 28, 1): patrol, the operating system in RAM
//! of examples/patrol, cruising toward an obstacle of a world file; the
//! room follows the drive motors' steps, closes the front bumper when the
//! outline meets the obstacle, and the ROM sets Master I/O bit 7 at that
//! moment; patrol backs away. Its path, drawn, is snapshotted.

mod rom_support;

use cards::Room;
use rom_support::{Session, build, examples_dir};
use romlib::symbols::IOBYTE;

/// A room of 3 by 2 metres, a post 20 cm round in front of the robot,
/// which stands at (100, 100) facing east: its front (15 cm from the
/// axle) is 25 cm from the post.
const ROOM: &str = r#"
walls = [[0, 0], [300, 0], [300, 200], [0, 200]]

[[obstacle]]
circle = { x = 160, y = 100, radius = 20 }

[robot]
x = 100
y = 100
heading = 0
"#;

#[test]
fn patrol_meets_the_post_sets_master_io_bit_7_then_backs_away() {
    let room = Room::load("room.toml", ROOM).expect("the world file loads");
    let view = room.view();
    let mut s = Session::new();
    s.robot.set_surroundings(Box::new(room));
    let patrol = build(&[examples_dir().join("patrol/patrol.s")], "scorpion-os");
    s.robot.load_image(&patrol).expect("patrol loads");
    s.send("/2A1");
    let io = |s: &Session| s.robot.robot().board().memory()[usize::from(IOBYTE)];
    let mut met = None;
    // A millisecond at a time, up to 4 s.
    for _ in 0..4000 {
        s.robot.run_for(1000).expect("runs");
        if io(&s) & 0x80 != 0 {
            met = Some(s.robot.cycles());
            break;
        }
    }
    let met = met.expect("the robot met the post within 4 s");
    let trail = view.trail();
    let &(closed_at, mask) = trail.bumps.first().expect("a bumper closed");
    assert_eq!(mask & 0x10, 0x10, "the front bumper (bit 4): {mask:08b}");
    assert!(
        met >= closed_at && met - closed_at <= 2000,
        "Master I/O bit 7 set at {met}, the bumper closed at {closed_at}"
    );
    let pose = view.pose().expect("a pose");
    // The outline meets the post with the axle 35 cm from its centre (the
    // two drives step a moment apart: a step's turn at most).
    assert!(
        (pose.at.x - 125.0).abs() < 0.2 && (pose.at.y - 100.0).abs() < 0.1,
        "met at {pose:?}"
    );
    // Backing away: the robot goes west, and the bumper opens.
    s.robot.run_for(400_000).expect("runs");
    let after = view.pose().expect("a pose");
    assert!(after.at.x < pose.at.x - 5.0, "backed away to {after:?}");
    let trail = view.trail();
    assert!(
        trail
            .bumps
            .iter()
            .any(|&(at, mask)| at > closed_at && mask == 0),
        "the bumper opened: {:?}",
        trail.bumps
    );
}

/// Patrol's first four seconds in the room, as a picture: the trail
/// toward the post, the bump, the backing away and the turn.
#[test]
fn patrols_path_in_the_room_as_a_picture() {
    let room = Room::load("room.toml", ROOM).expect("the world file loads");
    let view = room.view();
    let mut s = Session::new();
    s.robot.set_surroundings(Box::new(room));
    let patrol = build(&[examples_dir().join("patrol/patrol.s")], "scorpion-os");
    s.robot.load_image(&patrol).expect("patrol loads");
    let sent = s.robot.cycles();
    s.send("/2A1");
    s.robot.run_until(4_000_000).expect("runs");
    insta::assert_snapshot!(view.svg(&[(sent, "/2A1".to_owned())]));
}

#[test]
fn a_mistake_in_a_world_file_is_located() {
    let text = "walls = [[0, 0], [300, 0]]\n";
    let error = Room::load("room.toml", text).expect_err("refused");
    assert_eq!(
        error.to_string(),
        "room.toml:1:9: the walls: 2 points, at least 3 needed"
    );
}
