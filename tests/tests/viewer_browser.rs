//! The result viewer over a real bus: a host with the real grasp-planner and
//! result-viewer plugin files plans the paper's can-at-breast-height scene;
//! the viewer answers `state`, `render` (a PNG) and `glb`, and its live web
//! page — opened in a headless Chromium (WebGL by SwiftShader) — draws the
//! robot, the hand and the can where they are, then follows a second plan
//! without being reloaded.
//!
//! Without Chromium (`.ci/run` installs Debian's `chromium`; elsewhere set
//! `TSUKAMI_CHROMIUM`) the browser test says that it did not run and why,
//! and passes; the bus test always runs.

#[path = "viewer_browser/cdp.rs"]
mod cdp;

use std::time::{Duration, Instant};

use serde_json::Value;
use tsukami::scenes::run_scene;
use tsukami_e2e::{
    cli_plugins_listing, models_dir, motion_entry, planner_entry, spawn_tsukami, test_config,
    viewer_entry, TestBus,
};
use tsukami_msgs::keys::{ROLE_RESULT_VIEWER, ROLE_TRAJECTORY_PLANNER};
use tsukami_scenes::paper_scene;

const TIMEOUT: Duration = Duration::from_secs(60);
/// The browser's page size.
const WIDTH: u32 = 800;
const HEIGHT: u32 = 600;

fn viewer(bus: &TestBus, command: &str, payload: &str) -> Value {
    let key = bus.client.keys().command(ROLE_RESULT_VIEWER, command);
    let bytes = bus
        .client
        .request_key(&key, payload.as_bytes(), TIMEOUT)
        .unwrap_or_else(|e| panic!("viewer/{command}: {e}"));
    serde_json::from_slice(&bytes).unwrap()
}

/// Polls `f` every 50 ms until it gives a value or `limit` passes.
fn wait_for<T>(what: &str, limit: Duration, mut f: impl FnMut() -> Option<T>) -> T {
    let end = Instant::now() + limit;
    loop {
        if let Some(v) = f() {
            return v;
        }
        assert!(Instant::now() < end, "waited {limit:?} for {what}");
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// Plans paper scene `name` with `seed` over the bus, checked as the paper
/// scene tests check it, and waits until the viewer has heard `plans` plans.
fn plan(bus: &TestBus, name: &str, seed: u64, plans: u64) -> (Value, Value) {
    let outcome = run_scene(
        &bus.client,
        &models_dir(),
        paper_scene(name).unwrap(),
        seed,
        TIMEOUT,
    );
    assert!(outcome.ok, "{name}: {:?}", outcome.problem);
    let state = wait_for(
        "the viewer to follow the plan",
        Duration::from_secs(10),
        || {
            let state = viewer(bus, "state", "{}");
            (state["counts"]["plans"].as_u64() >= Some(plans)).then_some(state)
        },
    );
    (
        state,
        serde_json::to_value(outcome.result.unwrap()).unwrap(),
    )
}

/// RGBA pixels of a PNG and its width.
fn pixels(png_bytes: &[u8]) -> (Vec<[u8; 3]>, u32) {
    let decoder = png::Decoder::new(std::io::Cursor::new(png_bytes));
    let mut reader = decoder.read_info().expect("a PNG");
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    let channels = info.color_type.samples();
    let px = buf[..info.buffer_size()]
        .chunks(channels)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    (px, info.width)
}

fn is_blue(p: [u8; 3]) -> bool {
    let [r, g, b] = p.map(i32::from);
    b > 100 && b > r + 50 && b > g + 15
}

fn is_orange(p: [u8; 3]) -> bool {
    let [r, g, b] = p.map(i32::from);
    r > 120 && r > b + 60 && g > b + 20
}

fn is_grey(p: [u8; 3]) -> bool {
    let (hi, lo) = (*p.iter().max().unwrap(), *p.iter().min().unwrap());
    hi - lo < 30 && lo > 90
}

/// Share of the pixels within `radius` of `at` that `test` accepts.
fn share(px: &[[u8; 3]], width: u32, at: [f64; 2], radius: i64, test: fn([u8; 3]) -> bool) -> f64 {
    let height = px.len() as i64 / i64::from(width);
    let (cx, cy) = (at[0].round() as i64, at[1].round() as i64);
    let mut n = (0, 0);
    for y in (cy - radius).max(0)..(cy + radius).min(height) {
        for x in (cx - radius).max(0)..(cx + radius).min(i64::from(width)) {
            n.1 += 1;
            n.0 += usize::from(test(px[(y * i64::from(width) + x) as usize]));
        }
    }
    n.0 as f64 / n.1.max(1) as f64
}

#[test]
fn the_viewer_follows_plans_and_answers_render_glb_and_state_over_the_bus() {
    let bus = TestBus::start(test_config(vec![planner_entry(), viewer_entry()]));
    let (state, _) = plan(&bus, "can_breast", 0, 1);
    assert_eq!(state["plan"]["grasp_type"], "fingertip4_mid", "{state}");
    assert!(state["plan"]["margin"].as_f64().unwrap() > 0.0);
    assert_eq!(state["contacts"].as_array().unwrap().len(), 4);
    // The object's OCP boxes, from the host's published set_object summary; the
    // grasped one marked.
    let ocp = state["ocp"].as_array().unwrap();
    assert!(!ocp.is_empty(), "{state}");
    let chosen: Vec<_> = ocp.iter().filter(|b| b["chosen"] == true).collect();
    assert_eq!(chosen.len(), 1, "{state}");
    assert_eq!(chosen[0]["region"], state["plan"]["ocp_region"]);
    let url = state["web"]["url"].as_str().expect("the page's address");
    assert!(url.starts_with("http://127.0.0.1:"), "{url}");

    let picture = viewer(&bus, "render", r#"{"width": 320, "height": 240}"#);
    assert_eq!(picture["posture"], "plan");
    use base64::Engine;
    let png = base64::engine::general_purpose::STANDARD
        .decode(picture["png_base64"].as_str().unwrap())
        .unwrap();
    let (px, width) = pixels(&png);
    assert_eq!((width, px.len()), (320, 320 * 240));
    // The camera looks at the grasp: the can is in the middle.
    assert!(share(&px, width, [160.0, 120.0], 40, is_blue) > 0.05);
    assert!(px.iter().any(|&p| is_orange(p)), "the hand is drawn");

    let glb = viewer(&bus, "glb", "{}");
    let bytes = base64::engine::general_purpose::STANDARD
        .decode(glb["glb_base64"].as_str().unwrap())
        .unwrap();
    assert_eq!(&bytes[..4], b"glTF");
    assert_eq!(glb["bytes"].as_u64(), Some(bytes.len() as u64));

    // Bad input: named, and the viewer keeps serving.
    let key = bus.client.keys().command(ROLE_RESULT_VIEWER, "render");
    let err = bus
        .client
        .request_key(&key, br#"{"width": 1}"#, TIMEOUT)
        .unwrap_err();
    assert!(err.to_string().contains("width"), "{err}");
    let err = bus
        .client
        .request_key(&key, br#"{"colour": 1}"#, TIMEOUT)
        .unwrap_err();
    assert!(err.to_string().contains("colour"), "{err}");
    assert_eq!(viewer(&bus, "state", "{}")["counts"]["plans"], 1);
}

/// Where the page draws `name` (`object` or a link), as the page computes it.
fn on_page(browser: &mut cdp::Browser, name: &str) -> [f64; 2] {
    let at = browser
        .eval(&format!("window.tsukamiViewer.screen({name:?})"))
        .unwrap();
    let at = at
        .as_array()
        .unwrap_or_else(|| panic!("{name} is not on the page"));
    [at[0].as_f64().unwrap(), at[1].as_f64().unwrap()]
}

/// Waits until the page shows generation `generation` or later with `plans`
/// plans, and a frame was drawn after.
fn page_shows(browser: &mut cdp::Browser, plans: u64) -> Value {
    wait_for("the page to draw the plan", TIMEOUT, || {
        let v = browser
            .eval("JSON.stringify(window.tsukamiViewer ?? null)")
            .ok()?;
        let v: Value = serde_json::from_str(v.as_str()?).ok()?;
        assert!(v["error"].is_null(), "the page failed: {}", v["error"]);
        (v["plans"].as_u64() >= Some(plans) && v["shown"] == v["generation"]).then_some(v)
    })
}

/// Plans the motion to `grasp`; the page's time slider then moves the hand
/// from where the motion starts (at rest) to where it ends (lifted).
fn the_slider_plays_the_planned_motion(bus: &TestBus, browser: &mut cdp::Browser, grasp: Value) {
    let request = serde_json::json!({"grasp": grasp, "seed": 0}).to_string();
    bus.client
        .command(ROLE_TRAJECTORY_PLANNER, "plan", request.as_bytes(), TIMEOUT)
        .expect("a motion to the grasp");
    let frames = wait_for("the page to load the motion", TIMEOUT, || {
        let motions = browser.eval("window.tsukamiViewer.motions").ok()?;
        let last = browser
            .eval("Number(document.getElementById('time').max)")
            .ok()?;
        (motions.as_u64() >= Some(1) && last.as_u64() > Some(0)).then(|| last.as_u64().unwrap())
    });
    let mut palm_at = |frame: u64| {
        let js = format!(
            "(() => {{ const s = document.getElementById('time'); s.value = {frame}; \
             s.dispatchEvent(new Event('input')); return window.tsukamiViewer.screen('r_palm'); }})()"
        );
        let at = browser.eval(&js).unwrap();
        [at[0].as_f64().unwrap(), at[1].as_f64().unwrap()]
    };
    let (start, end) = (palm_at(0), palm_at(frames));
    let moved = (start[0] - end[0]).hypot(start[1] - end[1]);
    assert!(
        moved > 20.0,
        "the palm moved {moved} px along the motion: {start:?} -> {end:?}"
    );
}

/// A screenshot, also kept as `<target tmp>/viewer_browser/<name>.png` to look at.
fn shot(browser: &mut cdp::Browser, name: &str) -> Vec<u8> {
    let png = browser.screenshot().unwrap();
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("viewer_browser");
    if std::fs::create_dir_all(&dir).is_ok() {
        let _ = std::fs::write(dir.join(format!("{name}.png")), &png);
    }
    png
}

#[test]
fn the_web_page_draws_robot_and_can_plays_the_motion_and_follows_a_new_plan() {
    let Some(chromium) = cdp::find_chromium() else {
        eprintln!("viewer_browser: NOT RUN: no chromium on this machine (.ci/run installs Debian's `chromium`; or set TSUKAMI_CHROMIUM)");
        return;
    };
    let bus = TestBus::start(test_config(vec![
        planner_entry(),
        viewer_entry(),
        motion_entry(),
    ]));
    let (state, grasp) = plan(&bus, "can_breast", 0, 1);
    let url = state["web"]["url"].as_str().unwrap().to_owned();
    let mut browser = match cdp::Browser::launch(&chromium, WIDTH, HEIGHT) {
        Ok(b) => b,
        Err(e) => panic!("{} is there but did not start: {e}", chromium.display()),
    };
    browser.navigate(&url).unwrap();
    let first = page_shows(&mut browser, 1);
    assert!(
        browser
            .eval("document.title")
            .unwrap()
            .as_str()
            .unwrap()
            .contains("fingertip4_mid"),
        "the panel names the grasp type"
    );
    let (px, width) = pixels(&shot(&mut browser, "can_breast"));
    assert_eq!(px.len() as u32, WIDTH * HEIGHT);
    let can = on_page(&mut browser, "object");
    let palm = on_page(&mut browser, "r_palm");
    let forearm = on_page(&mut browser, "r_forearm_link");
    let blue = share(&px, width, can, 12, is_blue);
    let orange = share(&px, width, palm, 12, is_orange);
    let grey = share(&px, width, forearm, 12, is_grey);
    assert!(blue > 0.15, "the can (blue) at {can:?}: {blue}");
    assert!(orange > 0.2, "the hand (orange) at {palm:?}: {orange}");
    assert!(grey > 0.2, "the arm (grey) at {forearm:?}: {grey}");
    the_slider_plays_the_planned_motion(&bus, &mut browser, grasp);

    // A new plan in another world: the open page follows it.
    plan(&bus, "can_waist", 0, 2);
    let second = page_shows(&mut browser, 2);
    assert_ne!(second["worldVersion"], first["worldVersion"]);
    let title = browser.eval("document.title").unwrap();
    assert!(
        title.as_str().unwrap().contains("fingertip3_mid"),
        "{title}"
    );
    let (px, width) = pixels(&shot(&mut browser, "can_waist"));
    let can = on_page(&mut browser, "object");
    let blue = share(&px, width, can, 12, is_blue);
    assert!(blue > 0.15, "the moved can (blue) at {can:?}: {blue}");
}

#[test]
fn the_default_host_loads_the_viewer_and_prints_where_its_page_is() {
    let port = tsukami::bus::free_loopback_port().unwrap();
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let namespace = format!("viewer-default-{port}");
    let mut host = spawn_tsukami(&["run", "--listen", &endpoint, "--namespace", &namespace]);
    let listing = cli_plugins_listing(&endpoint, &namespace);
    let viewer = listing["plugins"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["roles"][0] == ROLE_RESULT_VIEWER)
        .unwrap_or_else(|| panic!("no result-viewer in {listing}"));
    assert_eq!(viewer["name"], "tsukami-result-viewer");
    // The log names the page's address (17448, or a free port when taken).
    let stderr = host.0.stderr.take().unwrap();
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        use std::io::BufRead;
        for line in std::io::BufReader::new(stderr)
            .lines()
            .map_while(Result::ok)
        {
            if line.contains("result viewer: open http://127.0.0.1:") {
                let _ = tx.send(line);
            }
        }
    });
    let line = rx
        .recv_timeout(TIMEOUT)
        .expect("the host prints the viewer's address");
    assert!(line.contains("in a browser"), "{line}");
}
