//! The scanner sees the obstacles in its direction (issue 28, 1): in a
//! room with one post, a horizontal scan (`/3H##`, then `/1S`) reads
//! higher at the steps pointing at the post than at open floor, and the
//! same run twice reads the same.

mod rom_support;

use cards::Room;
use cards::room::scanner;
use rom_support::Session;
use romlib::protocol::Answer;

/// A room of 3 by 2 metres, a post 20 cm round at (160, 100), and the
/// robot at (100, 100) facing `heading` degrees: the post's near side is
/// 25 cm from the robot's outline (radius 15) when it faces east.
fn room(heading: u32) -> String {
    format!(
        "walls = [[0, 0], [300, 0], [300, 200], [0, 200]]\n\
         [[obstacle]]\ncircle = {{ x = 160, y = 100, radius = 20 }}\n\
         [robot]\nx = 100\ny = 100\nheading = {heading}\n"
    )
}

/// The scanner buffer after `/3H{steps}`, steps -steps to +steps.
fn scan(heading: u32, steps: u8) -> Vec<u8> {
    let room = Room::load("room.toml", &room(heading)).expect("the world file loads");
    let mut s = Session::new();
    s.robot.set_surroundings(Box::new(room));
    s.send(&format!("/3H{steps:02}"));
    s.wait_ms(2500);
    assert_eq!(s.ask("/1X"), "X00\r", "the scan is done");
    let Some(Answer::Scan(scan)) = s.send("/1S") else {
        panic!("/1S answers S...")
    };
    assert_eq!(scan.data.len(), 2 * usize::from(steps) + 1);
    scan.data
}

#[test]
fn a_scan_facing_the_post_reads_higher_than_one_facing_open_floor() {
    let post = scan(0, 5);
    let away = scan(180, 5);
    // Straight ahead: the post 25 cm from the outline, by the formula.
    assert_eq!(post[5], scanner::reading(Some(25.0)), "{post:02X?}");
    // Facing west, the wall 100 cm off, 85 from the outline.
    assert_eq!(away[5], scanner::reading(Some(85.0)), "{away:02X?}");
    for (step, (p, a)) in post.iter().zip(&away).enumerate() {
        assert!(p > a, "step {step}: {post:02X?} against {away:02X?}");
    }
    assert_eq!(post, scan(0, 5), "the same run reads the same");
}

#[test]
fn a_plus_step_turns_the_scanner_right() {
    // Facing north, the post is 90° to the right: 50 steps of 1.8°.
    let data = scan(90, 60);
    let centre = 60;
    let right = data[centre + 50];
    let left = data[centre - 50];
    assert_eq!(right, scanner::reading(Some(25.0)), "{data:02X?}");
    assert_eq!(left, scanner::reading(Some(85.0)), "the west wall");
    assert!(right > data[centre], "more than the north wall ahead");
}

/// A world script's `scene_at` wins where it sets the reading; the room
/// fills the rest of the row.
#[test]
fn a_world_script_wins_where_it_sets_the_scene() {
    let script = "fn init() { wake_at(ms(1)); }\nfn wake(now) { scene_at(0, 0, 7); }\n";
    let mut room = Room::load("room.toml", &room(0)).expect("the world file loads");
    let world = cards::ScriptWorld::load("world.rhai", script).expect("the script loads");
    room.add(Box::new(world));
    let mut s = Session::new();
    s.robot.set_surroundings(Box::new(room));
    s.send("/3H02");
    s.wait_ms(2500);
    let Some(Answer::Scan(scan)) = s.send("/1S") else {
        panic!("/1S answers S...")
    };
    assert_eq!(scan.data[2], 7, "{:02X?}", scan.data);
    assert!(scan.data[1] > 0xD0, "the room's post: {:02X?}", scan.data);
}
