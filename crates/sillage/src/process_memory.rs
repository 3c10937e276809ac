//! The resident memory of this process (Linux `/proc/self/status`), for the benches' peak
//! memory columns; `None` where the platform does not tell.

/// A `VmXXX:` line of `/proc/self/status`, MiB.
fn status_mib(field: &str) -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with(field))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

/// Peak resident memory of this process so far (Linux `VmHWM`), MiB.
pub fn peak_rss_mib() -> Option<f64> {
    status_mib("VmHWM:")
}

/// Resets the peak resident memory to the current one (Linux ≥ 4.0, `clear_refs` 5), so
/// that the next [`peak_rss_mib`] measures what ran in between; false where unsupported.
pub fn reset_peak_rss() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

/// Current resident memory of this process (Linux `VmRSS`), MiB.
pub fn rss_mib() -> Option<f64> {
    status_mib("VmRSS:")
}
