//! Progress of long work: scene parsing, texture decoding, octree builds, path-traced
//! renders. On a terminal a bar shows the items done and the time left; elsewhere (CI
//! logs, pipes) the bar stays hidden and work expected to run longer than a few seconds
//! logs a plain line at each quarter instead.

use std::io::{BufRead, Read};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Work expected to take less than this in all logs no quarter lines.
const QUIET: Duration = Duration::from_secs(2);

/// The progress of `total` items of one phase. Shared across threads by reference.
pub struct Progress {
    what: String,
    unit: &'static str,
    total: u64,
    done: AtomicU64,
    /// The last quarter logged (hidden bar only).
    quarter: AtomicU64,
    start: Instant,
    bar: ProgressBar,
}

impl Progress {
    /// `what` names the phase ("decoding textures"); items are counted without a unit.
    pub fn new(what: &str, total: u64) -> Self {
        Self::with_unit(what, "", total)
    }

    /// As [`Progress::new`], with the items' unit ("samples per pixel").
    pub fn with_unit(what: &str, unit: &'static str, total: u64) -> Self {
        let unit_text = if unit.is_empty() {
            String::new()
        } else {
            format!(" {unit}")
        };
        Self::styled(what, unit, total, &format!("{{pos}}/{{len}}{unit_text}"))
    }

    /// Progress through `total` bytes (shown in KiB, MiB, GiB).
    pub fn bytes(what: &str, total: u64) -> Self {
        Self::styled(what, "bytes", total, "{bytes}/{total_bytes}")
    }

    fn styled(what: &str, unit: &'static str, total: u64, count: &str) -> Self {
        let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
        bar.set_style(
            ProgressStyle::with_template(&format!(
                "{{msg}} {{bar:40}} {count}, {{elapsed}} so far, {{eta}} left"
            ))
            .expect("a valid progress template"),
        );
        bar.set_message(what.to_string());
        Self {
            what: what.to_string(),
            unit,
            total,
            done: AtomicU64::new(0),
            quarter: AtomicU64::new(0),
            start: Instant::now(),
            bar,
        }
    }

    /// One more item done.
    pub fn advance(&self) {
        let done = self.done.fetch_add(1, Ordering::Relaxed) + 1;
        self.show(done);
    }

    /// `done` items done in all.
    pub fn set(&self, done: u64) {
        self.done.store(done, Ordering::Relaxed);
        self.show(done);
    }

    fn show(&self, done: u64) {
        self.bar.set_position(done);
        if !self.bar.is_hidden() {
            return;
        }
        let quarter = 4 * done / self.total.max(1);
        let last = self.quarter.fetch_max(quarter, Ordering::Relaxed);
        let elapsed = self.start.elapsed().as_secs_f64();
        // The whole work's time as the part done predicts it.
        let expected = elapsed * self.total as f64 / done.max(1) as f64;
        if quarter > last && quarter < 4 && expected >= QUIET.as_secs_f64() {
            let left = elapsed * (self.total - done.min(self.total)) as f64 / done.max(1) as f64;
            log::info!(
                "{}: {done} of {}{}{} done, {elapsed:.0} s so far, about {left:.0} s left",
                self.what,
                self.total,
                if self.unit.is_empty() { "" } else { " " },
                self.unit
            );
        }
    }

    /// Removes the bar (the caller logs the phase's result).
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

/// A reader that reports the bytes consumed from it to a [`Progress`].
pub struct ProgressReader<'a, R> {
    inner: R,
    progress: &'a Progress,
    consumed: u64,
}

impl<'a, R: BufRead> ProgressReader<'a, R> {
    pub fn new(inner: R, progress: &'a Progress) -> Self {
        Self {
            inner,
            progress,
            consumed: 0,
        }
    }

    fn count(&mut self, bytes: usize) {
        self.consumed += bytes as u64;
        self.progress.set(self.consumed);
    }
}

impl<R: BufRead> Read for ProgressReader<'_, R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.count(n);
        Ok(n)
    }
}

impl<R: BufRead> BufRead for ProgressReader<'_, R> {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        self.inner.fill_buf()
    }

    fn consume(&mut self, amount: usize) {
        self.inner.consume(amount);
        self.count(amount);
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        // A phase that failed leaves no bar behind its error message.
        self.bar.finish_and_clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_across_threads() {
        let progress = Progress::new("test", 1000);
        std::thread::scope(|s| {
            for _ in 0..4 {
                s.spawn(|| (0..250).for_each(|_| progress.advance()));
            }
        });
        assert_eq!(progress.done.load(Ordering::Relaxed), 1000);
        progress.set(10);
        assert_eq!(progress.bar.position(), 10);
        progress.finish();
    }

    #[test]
    fn reader_reports_the_bytes_consumed() {
        let text = "line one\nline two\n";
        let progress = Progress::bytes("test", text.len() as u64);
        let mut reader = ProgressReader::new(text.as_bytes(), &progress);
        let mut first = String::new();
        reader.read_line(&mut first).unwrap();
        assert_eq!(progress.done.load(Ordering::Relaxed), 9);
        let mut rest = Vec::new();
        reader.read_to_end(&mut rest).unwrap();
        assert_eq!(progress.done.load(Ordering::Relaxed), text.len() as u64);
    }
}
