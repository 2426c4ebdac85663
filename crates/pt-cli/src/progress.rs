//! What a program shows besides its output: the library's warnings, asset downloads, and a
//! render's progress, on stderr, and only on a terminal for the bars.

use std::io::IsTerminal;
use std::sync::{Mutex, Once, OnceLock};

use indicatif::{ProgressBar, ProgressStyle};
use pt_core::{
    Camera, Light, Material, Progress, RenderControl, RenderError, RenderOptions, RenderOutput,
    Scene,
};

static PROGRAM: OnceLock<&'static str> = OnceLock::new();

/// The program's name given to [`init`] (`pt` before it is called).
pub(crate) fn program() -> &'static str {
    PROGRAM.get().copied().unwrap_or("pt")
}

/// Install what every program shows its user besides its own output: the library's warnings
/// on stderr (`RUST_LOG=info`, `debug`, ... shows more, `RUST_LOG=error` fewer) and, for each
/// asset fetched on first use, one line saying what comes from where and a progress bar on a
/// terminal. [`crate::parse`] calls it; later calls do nothing.
pub fn init(name: &'static str) {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        let _ = PROGRAM.set(name);
        let inner =
            env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn"))
                .format_timestamp(None)
                .build();
        let level = inner.filter().max(log::LevelFilter::Warn);
        if log::set_boxed_logger(Box::new(Capturing { inner })).is_ok() {
            log::set_max_level(level);
        }
        download_progress(name);
    });
}

/// The process's logger: env_logger's output, and every warning kept for [`warnings`] (so
/// `pt info` can list what a file uses that pt ignores).
struct Capturing {
    inner: env_logger::Logger,
}

static WARNINGS: Mutex<Vec<String>> = Mutex::new(Vec::new());

impl log::Log for Capturing {
    fn enabled(&self, metadata: &log::Metadata<'_>) -> bool {
        metadata.level() <= log::Level::Warn || self.inner.enabled(metadata)
    }

    fn log(&self, record: &log::Record<'_>) {
        if record.level() <= log::Level::Warn {
            WARNINGS
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner)
                .push(record.args().to_string());
        }
        if self.inner.matches(record) {
            self.inner.log(record);
        }
    }

    fn flush(&self) {
        self.inner.flush();
    }
}

/// The warnings logged since the last call (the process's, once [`init`] ran).
pub fn warnings() -> Vec<String> {
    std::mem::take(
        &mut *WARNINGS
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner),
    )
}

fn download_progress(name: &'static str) {
    use pt_scene::assets::{DownloadEvent, set_download_observer};
    let bar: Mutex<Option<ProgressBar>> = Mutex::new(None);
    set_download_observer(move |event| {
        let mut bar = bar
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        match *event {
            DownloadEvent::Started {
                name: asset,
                url,
                size,
                dest,
            } => {
                eprintln!(
                    "{name}: fetching asset {asset} ({:.1} MiB) from {url} into {}",
                    size as f64 / (1u64 << 20) as f64,
                    dest.display()
                );
                *bar = std::io::stderr().is_terminal().then(|| {
                    let b = ProgressBar::new(size);
                    b.set_style(
                        ProgressStyle::with_template(
                            "{prefix} [{elapsed_precise}] {wide_bar} {bytes}/{total_bytes} ({bytes_per_sec}, eta {eta})",
                        )
                        .expect("valid template"),
                    );
                    b.set_prefix(name);
                    b
                });
            }
            DownloadEvent::Progress { bytes, total, .. } => {
                if let Some(b) = bar.as_ref() {
                    if total > 0 {
                        b.set_length(total);
                    }
                    b.set_position(bytes);
                }
            }
            _ => {
                if let Some(b) = bar.take() {
                    b.finish_and_clear();
                }
            }
        }
    });
}

/// Render with a progress bar (tiles, elapsed, ETA) on stderr when `show` and stderr is a
/// terminal.
pub(crate) fn render<M: Material, L: Light, C: Camera>(
    name: &'static str,
    show: bool,
    scene: &Scene<M, L>,
    camera: &C,
    options: &RenderOptions,
) -> Result<RenderOutput, RenderError> {
    with_progress(name, show, |control| {
        pt_core::render(scene, camera, options, Some(control))
    })
}

/// Run `render` with a control that reports tiles to the progress bar.
fn with_progress(
    name: &'static str,
    show: bool,
    render: impl FnOnce(&RenderControl<'_>) -> Result<RenderOutput, RenderError>,
) -> Result<RenderOutput, RenderError> {
    let bar = (show && std::io::stderr().is_terminal()).then(|| {
        let bar = ProgressBar::new(0);
        bar.set_style(
            ProgressStyle::with_template(
                "{prefix} [{elapsed_precise}] {wide_bar} {pos}/{len} tiles (eta {eta})",
            )
            .expect("valid template"),
        );
        bar.set_prefix(name);
        bar
    });
    let on_tile = |p: Progress| {
        if let Some(bar) = &bar {
            bar.set_length(p.tiles_total as u64);
            bar.set_position(p.tiles_done as u64);
        }
    };
    let control = RenderControl::new().progress(&on_tile);
    let out = render(&control);
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    out
}
