//! `sillage tune` started as a child process for the tests, stopped when dropped.

// Each test binary uses part of this module.
#![allow(dead_code)]

use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};

/// A running `sillage tune` server.
pub struct TuneServer {
    child: Child,
    /// Its port on 127.0.0.1.
    pub port: u16,
}

impl TuneServer {
    /// Starts `sillage tune ARGS --port 0` and reads the address it prints first.
    pub fn start(args: &[&str]) -> TuneServer {
        let mut child = Command::new(env!("CARGO_BIN_EXE_sillage"))
            .arg("tune")
            .args(args)
            .args(["--port", "0"])
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("the sillage binary runs");
        let mut line = String::new();
        BufReader::new(child.stdout.take().expect("piped stdout"))
            .read_line(&mut line)
            .expect("sillage tune prints its address");
        let port = line
            .trim()
            .strip_prefix("http://127.0.0.1:")
            .and_then(|rest| rest.strip_suffix('/'))
            .and_then(|p| p.parse().ok())
            .unwrap_or_else(|| panic!("unexpected first line {line:?}"));
        TuneServer { child, port }
    }

    /// The page's address.
    pub fn url(&self) -> String {
        format!("http://127.0.0.1:{}/", self.port)
    }
}

impl Drop for TuneServer {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}
