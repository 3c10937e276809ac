//! A small W3C WebDriver client for the browser tests: Debian's `/usr/bin/chromium`, headless,
//! driven through `/usr/bin/chromedriver` over plain HTTP/1.1 on 127.0.0.1.

use std::net::TcpStream;
use std::process::{Child, Command, Stdio};
use std::time::Duration;

use serde_json::{Value, json};

use crate::http_client::{free_port, http, wait_until};

/// The key under which WebDriver returns an element reference.
const ELEMENT_KEY: &str = "element-6066-11e4-a52e-4f735466cecf";

/// A headless Chromium session; the session and chromedriver end when it is dropped.
pub struct Browser {
    driver: Child,
    port: u16,
    session: String,
    _profile: tempfile::TempDir,
}

impl Browser {
    /// Starts chromedriver on a free port and opens a session with a `width`×`height` window.
    pub fn start(width: u32, height: u32) -> Browser {
        let port = free_port();
        let driver = Command::new("/usr/bin/chromedriver")
            .arg(format!("--port={port}"))
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("/usr/bin/chromedriver runs (apt-get install chromium chromium-driver)");
        let profile = tempfile::tempdir().unwrap();
        let mut browser = Browser {
            driver,
            port,
            session: String::new(),
            _profile: profile,
        };
        wait_until("chromedriver", Duration::from_secs(15), || {
            TcpStream::connect(("127.0.0.1", port)).is_ok()
                && http(port, "GET", "/status", None).0 == 200
        });
        let args = [
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--disable-dev-shm-usage",
            "--hide-scrollbars",
            "--force-device-scale-factor=1",
            &format!("--user-data-dir={}", browser._profile.path().display()),
            &format!("--window-size={width},{height}"),
        ];
        let capabilities = json!({"capabilities": {"alwaysMatch": {
            "browserName": "chrome",
            "goog:chromeOptions": {"binary": "/usr/bin/chromium", "args": args},
        }}});
        let reply = browser.command("POST", "/session", Some(&capabilities));
        browser.session = reply["sessionId"]
            .as_str()
            .unwrap_or_else(|| panic!("no session: {reply}"))
            .to_string();
        browser
    }

    /// One WebDriver command; panics with the driver's message on an error status.
    fn command(&self, method: &str, path: &str, body: Option<&Value>) -> Value {
        let (status, bytes) = http(self.port, method, path, body);
        let reply: Value = serde_json::from_slice(&bytes).expect("JSON reply");
        assert_eq!(status, 200, "{method} {path}: {reply}");
        reply["value"].clone()
    }

    /// A command of this session (`path` after `/session/{id}`).
    fn session_command(&self, method: &str, path: &str, body: Option<&Value>) -> Value {
        let path = format!("/session/{}{path}", self.session);
        self.command(method, &path, body)
    }

    /// Opens `url`.
    pub fn goto(&self, url: &str) {
        self.session_command("POST", "/url", Some(&json!({ "url": url })));
    }

    /// Runs `script` (a function body; `return` gives the value) in the page.
    pub fn eval(&self, script: &str) -> Value {
        self.session_command(
            "POST",
            "/execute/sync",
            Some(&json!({"script": script, "args": []})),
        )
    }

    /// Waits until `script` returns `true`.
    pub fn wait_for(&self, script: &str) {
        wait_until(script, Duration::from_secs(15), || {
            self.eval(script) == Value::Bool(true)
        });
    }

    /// The element matching the CSS `selector`.
    pub fn find(&self, selector: &str) -> String {
        let found = self.session_command(
            "POST",
            "/element",
            Some(&json!({"using": "css selector", "value": selector})),
        );
        found[ELEMENT_KEY]
            .as_str()
            .unwrap_or_else(|| panic!("no element {selector}: {found}"))
            .to_string()
    }

    /// An element's rectangle in viewport px: x, y, width, height.
    pub fn rect(&self, element: &str) -> [f64; 4] {
        let r = self.session_command("GET", &format!("/element/{element}/rect"), None);
        ["x", "y", "width", "height"].map(|k| r[k].as_f64().expect("rect field"))
    }

    /// An element's rendered text.
    pub fn text(&self, element: &str) -> String {
        let t = self.session_command("GET", &format!("/element/{element}/text"), None);
        t.as_str().expect("text").to_string()
    }

    /// Moves the mouse to viewport position (`x`, `y`), px.
    pub fn move_mouse(&self, x: i64, y: i64) {
        let actions = json!({"actions": [{
            "type": "pointer", "id": "mouse", "parameters": {"pointerType": "mouse"},
            "actions": [{"type": "pointerMove", "duration": 0, "origin": "viewport", "x": x, "y": y}],
        }]});
        self.session_command("POST", "/actions", Some(&actions));
    }

    /// Clicks `element` (at its centre), as a user would.
    pub fn click(&self, element: &str) {
        self.session_command(
            "POST",
            &format!("/element/{element}/click"),
            Some(&json!({})),
        );
    }

    /// Presses and releases the left mouse button at viewport position (`x`, `y`), px.
    pub fn click_at(&self, x: i64, y: i64) {
        let actions = json!({"actions": [{
            "type": "pointer", "id": "mouse", "parameters": {"pointerType": "mouse"},
            "actions": [
                {"type": "pointerMove", "duration": 0, "origin": "viewport", "x": x, "y": y},
                {"type": "pointerDown", "button": 0},
                {"type": "pointerUp", "button": 0},
            ],
        }]});
        self.session_command("POST", "/actions", Some(&actions));
    }

    /// A screenshot of the viewport, decoded.
    pub fn screenshot(&self) -> image::RgbaImage {
        use base64::Engine;
        let encoded = self.session_command("GET", "/screenshot", None);
        let png = base64::engine::general_purpose::STANDARD
            .decode(encoded.as_str().expect("base64 text"))
            .expect("base64 PNG");
        image::load_from_memory(&png)
            .expect("a PNG screenshot")
            .to_rgba8()
    }
}

impl Drop for Browser {
    fn drop(&mut self) {
        if !self.session.is_empty() {
            let path = format!("/session/{}", self.session);
            let _ = std::panic::catch_unwind(|| http(self.port, "DELETE", &path, None));
        }
        let _ = self.driver.kill();
        let _ = self.driver.wait();
    }
}
