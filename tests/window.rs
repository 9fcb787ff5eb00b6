//! The viewer in a real window under Xvfb: open, render, resize, render, close, with
//! validation clean.

mod common;

use std::ffi::OsStr;
use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Output, Stdio};
use std::sync::Mutex;

use common::{assert_clean, stderr, temp_dir};

/// Panics naming the package when `tool` is missing: the README lists them, and a test
/// that returned early would count as passed.
fn require(tool: &str, package: &str) {
    assert!(
        Command::new(tool).arg("--help").output().is_ok(),
        "{tool} is not installed (Debian: apt-get install {package}; see the README)"
    );
}

/// One viewer at a time: the tests' windows would otherwise share the two cores, and a
/// storm whose viewer drew 6 frames in it (1.1 s each, beside the other window tests)
/// recreated its swapchain only 3 times.
static ONE_WINDOW: Mutex<()> = Mutex::new(());

/// An Xvfb server of its own, stopped on drop. `-displayfd` makes the server pick a free
/// display and write its number only once it accepts connections: `xvfb-run -a` guesses
/// the number from lock files and waits on a signal, and under load its viewer once found
/// no server (CI, "Failed to open connection to X server").
///
/// `-noreset`: an X server resets when its last client disconnects, and a client that
/// connects during the reset is refused. The scripts' `xdotool search` polls connect and
/// disconnect while the viewer starts, so without it the viewer's own connection failed
/// now and then (the same message); a shell loop of `xdotool` clients beside such polls
/// had 20 of 300 connections refused without the flag, none with it.
struct VirtualScreen {
    server: Child,
    display: String,
}

impl VirtualScreen {
    fn start() -> Self {
        require("Xvfb", "xvfb");
        let mut server = Command::new("Xvfb")
            .args([
                "-displayfd",
                "1",
                "-screen",
                "0",
                "1024x768x24",
                "-nolisten",
                "tcp",
                "-noreset",
            ])
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("starting Xvfb");
        let mut number = String::new();
        BufReader::new(server.stdout.take().expect("Xvfb's stdout"))
            .read_line(&mut number)
            .expect("reading Xvfb's display number");
        let number = number.trim();
        assert!(
            !number.is_empty() && number.bytes().all(|b| b.is_ascii_digit()),
            "Xvfb reported no display ({number:?}); did it fail to start?"
        );
        let display = format!(":{number}");
        Self { server, display }
    }
}

impl Drop for VirtualScreen {
    fn drop(&mut self) {
        let _ = self.server.kill();
        let _ = self.server.wait();
    }
}

/// Runs `program` with `args` in a virtual screen, validation on, and checks it clean.
fn under_xvfb(program: &OsStr, args: &[&OsStr]) -> Output {
    // A failed test poisons the lock; the next may still run.
    let _one = ONE_WINDOW.lock().unwrap_or_else(|e| e.into_inner());
    let screen = VirtualScreen::start();
    let output = Command::new(program)
        .args(args)
        .env("DISPLAY", &screen.display)
        .env_remove("WAYLAND_DISPLAY")
        .env("VOXCONE_VALIDATION", "1")
        .env("RUST_LOG", "info")
        .output()
        .expect("running the program under Xvfb");
    drop(screen);
    eprintln!("{}", stderr(&output));
    assert_clean(&output);
    output
}

/// Runs `voxcone view` with `args` in a virtual screen, validation on.
fn view_under_xvfb(args: &[&OsStr]) -> Output {
    let mut all = vec![OsStr::new("view")];
    all.extend_from_slice(args);
    under_xvfb(OsStr::new(env!("CARGO_BIN_EXE_voxcone")), &all)
}

#[test]
fn viewer_opens_resizes_and_closes_under_xvfb() {
    let shot = temp_dir("window").join("view.png");
    let args = [
        "--frames",
        "30",
        "--size",
        "320x240",
        "--resize-to",
        "400x300",
        "--screenshot",
    ];
    let mut args: Vec<&OsStr> = args.iter().map(OsStr::new).collect();
    args.push(shot.as_os_str());
    let output = view_under_xvfb(&args);
    let err = stderr(&output);
    assert!(err.contains("resizing the window to 400x300"), "{err}");
    let (image, _) = voxcone::imageio::load_rgb(&shot).unwrap();
    assert_eq!(
        (image.width, image.height),
        (400, 300),
        "the swapchain did not follow the resize"
    );
    assert!(
        image.data.iter().any(|&v| v > 0.1),
        "the window shows nothing"
    );
}

/// `view --gi path` accumulates while nothing moves and starts again when a light moves:
/// after 8 frames of 64 samples per pixel (a 64x64 window), 512 samples in a still scene,
/// 64 with an orbiting light.
#[test]
fn path_tracer_accumulates_until_a_light_moves() {
    let dir = temp_dir("window_path");
    let obj = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/cornell.obj");
    for (orbit, expected) in [
        ("", 512),
        (
            "orbit = { center = [0, 1, 0], axis = [0, 1, 0], period_s = 8 }\n",
            64,
        ),
    ] {
        let scene = dir.join("scene.toml");
        std::fs::write(
            &scene,
            format!(
                "[camera]\nposition = [0.0, 1.0, 3.9]\ntarget = [0.0, 1.0, 0.0]\nfov_y_deg = 39.3\n\
                 [[mesh]]\npath = {obj:?}\n\
                 [[light]]\nkind = \"point\"\nposition = [0.3, 1.5, 0.0]\nintensity = [3.0, 3.0, 3.0]\n{orbit}"
            ),
        )
        .unwrap();
        let args = [
            "--gi", "path", "--spp", "100000", "--frames", "8", "--size", "64x64",
        ];
        let mut args: Vec<&OsStr> = args.iter().map(OsStr::new).collect();
        args.insert(0, scene.as_os_str());
        let output = view_under_xvfb(&args);
        let err = stderr(&output);
        let shown = format!("the last frame showed {expected} of 100000 samples per pixel");
        assert!(
            err.contains(&shown),
            "{orbit:?}: expected {shown:?} in {err}"
        );
    }
}

/// Resizes the viewer's window 100 times to sizes down to 1x1 (`xdotool windowsize`,
/// 20 ms apart, whatever frame is in flight, and a second at each 1x1), then unmaps and maps it again (Xvfb has no
/// window manager to minimize to; unmapping is what minimizing does to the window), then
/// quits with Escape. Validation stays clean: a swapchain semaphore destroyed while a
/// command buffer still used it failed 6 of 8 such storms (issue 22, item 10).
const STORM: &str = r#"
voxcone=$1; shift
"$voxcone" view --size 256x256 &
pid=$!
"#;

/// The end of a script's first part: `$wid` is the window of the viewer `$pid`, else the
/// script fails.
const WAIT_FOR_WINDOW: &str = r#"
wid=""
for i in $(seq 300); do
    wid=$(xdotool search --pid $pid 2>/dev/null | head -1)
    [ -n "$wid" ] && break
    sleep 0.1
done
[ -n "$wid" ] || { echo "the viewer opened no window" >&2; kill $pid; exit 2; }
"#;

/// The storm itself, after [`WAIT_FOR_WINDOW`].
const STORM_RESIZES: &str = r#"
sleep 1
n=0
for size in "$@"; do
    xdotool windowsize $wid ${size%x*} ${size#*x}
    n=$((n + 1))
    # A second at each tenth size (the 1x1 ones), so that frames (0.6 to 1.1 s each
    # with validation on two cores) come at ten points of the storm at least.
    if [ $((n % 10)) -eq 1 ]; then sleep 1; else sleep 0.02; fi
done
xdotool windowunmap --sync $wid
sleep 0.5
xdotool windowmap --sync $wid
sleep 0.5
xdotool windowfocus --sync $wid
xdotool key Escape
wait $pid
"#;

#[test]
fn resize_storms_keep_validation_clean() {
    require("xdotool", "xdotool");
    let dir = temp_dir("storm");
    let script = dir.join("storm.sh");
    std::fs::write(&script, [STORM, WAIT_FOR_WINDOW, STORM_RESIZES].concat()).unwrap();
    // A small deterministic generator (xorshift): the same storms every run.
    let mut state = 0x2545_f491_u32;
    let mut next = |n: u32| {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        1 + state % n
    };
    for storm in 0..2 {
        let sizes: Vec<String> = (0..100)
            .map(|i| match i % 10 {
                // Among them 1x1 and one pixel wide or high.
                0 => "1x1".to_string(),
                3 => format!("1x{}", next(600)),
                6 => format!("{}x1", next(600)),
                _ => format!("{}x{}", next(600), next(600)),
            })
            .collect();
        let mut args = vec![
            script.as_os_str(),
            OsStr::new(env!("CARGO_BIN_EXE_voxcone")),
        ];
        args.extend(sizes.iter().map(OsStr::new));
        let output = under_xvfb(OsStr::new("sh"), &args);
        let err = stderr(&output);
        let recreations: u64 = err
            .split(" swapchain recreations")
            .next()
            .and_then(|s| s.rsplit(' ').next())
            .and_then(|n| n.parse().ok())
            .unwrap_or_else(|| panic!("storm {storm}: no summary in {err}"));
        eprintln!("storm {storm}: {recreations} swapchain recreations");
        // Resizes faster than frames coalesce; each frame sees the latest size (alone,
        // 11 to 24 recreations a storm), so the floor only asks that the storm did reach
        // the swapchain several times.
        assert!(
            recreations >= 5,
            "storm {storm}: only {recreations} recreations"
        );
    }
}

/// Opens the viewer at 800x500, resizes its window to 640x400, clicks the panel's "off"
/// technique (at (20, 53): the panel's layout is fixed, egui bringing its own fonts), and
/// lets it save its last frame after `--frames`.
const PANEL_CLICK: &str = r#"
voxcone=$1; shot=$2
"$voxcone" view --size 800x500 --frames 120 --screenshot "$shot" &
pid=$!
"#;

/// The click, after [`WAIT_FOR_WINDOW`].
const PANEL_CLICK_ACTIONS: &str = r#"
sleep 3
xdotool windowsize --sync $wid 640 400
sleep 1
# egui presses what the pointer hovered over in an earlier frame: move, then click.
xdotool mousemove --window $wid 20 53
sleep 1
xdotool click 1
wait $pid
"#;

/// Mean absolute difference of two images' RGB over columns `x0..x1` (same size).
fn difference(
    a: &voxcone::imageio::RgbImage,
    b: &voxcone::imageio::RgbImage,
    x0: u32,
    x1: u32,
) -> f32 {
    assert_eq!((a.width, a.height), (b.width, b.height));
    let mut sum = 0.0f64;
    let mut count = 0usize;
    for y in 0..a.height {
        for x in x0..x1 {
            let i = 3 * (y * a.width + x) as usize;
            for c in 0..3 {
                sum += f64::from((a.data[i + c] - b.data[i + c]).abs());
                count += 1;
            }
        }
    }
    (sum / count as f64) as f32
}

/// The settings panel (egui) under Xvfb with validation on: it is drawn over the image
/// (against `--no-ui`), a click on its "off" technique rebuilds the renderer without GI
/// (the image then matches a `--gi off` viewer's, and not the dense one's), the window
/// resizes with the panel on it, and the viewer exits cleanly.
#[test]
fn settings_panel_draws_switches_the_technique_and_resizes() {
    require("xdotool", "xdotool");
    let dir = temp_dir("panel");
    let shot = |name: &str, extra: &[&str]| {
        let path = dir.join(name);
        let mut args: Vec<&OsStr> = ["--frames", "12", "--size", "640x400", "--screenshot"]
            .iter()
            .map(OsStr::new)
            .collect();
        args.push(path.as_os_str());
        args.extend(extra.iter().map(OsStr::new));
        view_under_xvfb(&args);
        voxcone::imageio::load_rgb(&path).unwrap().0
    };
    let panel = shot("panel.png", &[]);
    let bare = shot("bare.png", &["--no-ui"]);
    let off = shot("off.png", &["--gi", "off"]);
    // The panel takes the left 300 pixels.
    let over_panel = difference(&panel, &bare, 0, 300);
    let beside = difference(&panel, &bare, 320, 640);
    eprintln!("panel vs --no-ui: {over_panel:.4} over the panel, {beside:.4} beside it");
    assert!(over_panel > 0.05, "no panel drawn: {over_panel}");
    assert!(
        beside < 0.01,
        "the panel changed the image beside it: {beside}"
    );

    let script = dir.join("panel.sh");
    std::fs::write(
        &script,
        [PANEL_CLICK, WAIT_FOR_WINDOW, PANEL_CLICK_ACTIONS].concat(),
    )
    .unwrap();
    let clicked_path = dir.join("clicked.png");
    let output = under_xvfb(
        OsStr::new("sh"),
        &[
            script.as_os_str(),
            OsStr::new(env!("CARGO_BIN_EXE_voxcone")),
            clicked_path.as_os_str(),
        ],
    );
    let err = stderr(&output);
    assert!(
        err.contains("rebuilding the renderer"),
        "the click did nothing: {err}"
    );
    let clicked = voxcone::imageio::load_rgb(&clicked_path).unwrap().0;
    assert_eq!((clicked.width, clicked.height), (640, 400), "not resized");
    let to_off = difference(&clicked, &off, 320, 640);
    let to_dense = difference(&clicked, &panel, 320, 640);
    eprintln!("after the click: {to_off:.4} from --gi off, {to_dense:.4} from dense");
    assert!(
        to_off < 0.01 && to_dense > 3.0 * to_off.max(0.003),
        "{to_off} {to_dense}"
    );
}
