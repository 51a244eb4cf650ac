//! What a report says about where and when it was measured.

use std::time::{Instant, SystemTime, UNIX_EPOCH};

/// Where a page's header says how long its command took: replaced by
/// [`stamp_duration`] once the page is complete.
pub const TOOK: &str = "{took}";

/// `page` with [`TOOK`] replaced by the wall time since `start` (so every
/// generated page names its command and how long it took).
pub fn stamp_duration(page: String, start: Instant) -> String {
    page.replace(TOOK, &format!("{:.0} s", start.elapsed().as_secs_f64()))
}

/// Today's date (UTC) as `YYYY-MM-DD`.
pub fn today() -> String {
    let secs = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let (y, m, d) = civil_from_days((secs / 86_400) as i64);
    format!("{y:04}-{m:02}-{d:02}")
}

/// The proleptic Gregorian date of `days` since 1970-01-01 (H. Hinnant's
/// `civil_from_days`, valid for any day count of this era).
fn civil_from_days(days: i64) -> (i64, u32, u32) {
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    let y = yoe + era * 400 + i64::from(m <= 2);
    (y, m, d)
}

/// The cores available to this process and, where `/proc/cpuinfo` tells
/// it, the processor model: "2 cores (Intel Xeon ...)".
pub fn description() -> String {
    let cores = std::thread::available_parallelism().map_or(1, usize::from);
    let model = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|info| {
            info.lines()
                .find_map(|l| l.strip_prefix("model name"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, m)| m.trim().to_owned())
        });
    let plural = if cores == 1 { "core" } else { "cores" };
    match model {
        Some(m) => format!("{cores} {plural} ({m})"),
        None => format!("{cores} {plural}"),
    }
}

/// The 1-minute load average from `/proc/loadavg`, if the system tells it:
/// other work on the machine slows the timed runs.
pub fn load_average() -> Option<f64> {
    std::fs::read_to_string("/proc/loadavg")
        .ok()?
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

/// Resets the process's peak resident memory (Linux: `5` to
/// `/proc/self/clear_refs`), so that [`peak_mb`] measures what follows.
pub fn reset_peak() {
    let _ = std::fs::write("/proc/self/clear_refs", "5");
}

/// The peak resident memory since [`reset_peak`] (`VmHWM`), in MB, where
/// the system reports it.
pub fn peak_mb() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

/// Runs `f`, returning its result, its wall time in seconds and the peak
/// resident memory it reached in MB (where the system reports it).
pub fn measured<T>(f: impl FnOnce() -> T) -> (T, f64, Option<f64>) {
    reset_peak();
    let started = std::time::Instant::now();
    let result = f();
    (result, started.elapsed().as_secs_f64(), peak_mb())
}

/// One line on the terminal for a finished (or failed) run.
pub fn print_run(what: &str, steps: usize, iterations: usize, seconds: f64, failure: Option<&str>) {
    println!(
        "{what}: {steps} steps, {iterations} iterations, {seconds:.1} s{}",
        failure.map_or(String::new(), |f| format!(", failed: {f}"))
    );
}

#[cfg(test)]
mod tests {
    use super::civil_from_days;

    #[test]
    fn known_dates() {
        assert_eq!(civil_from_days(0), (1970, 1, 1));
        assert_eq!(civil_from_days(11_016), (2000, 2, 29));
        assert_eq!(civil_from_days(20_780), (2026, 11, 23));
    }
}
