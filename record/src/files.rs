//! The recorder's writer thread: one MCAP file, or a series of them split by size or age,
//! each complete in itself (its schemas and channels declared again, its own summary).

use std::collections::HashMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;
use std::sync::mpsc::Receiver;
use std::time::Instant;

use crate::mcap::{McapWriter, WriteError};
use crate::recorder::{Counters, Item, RecordConfig, RecordError};

/// A channel as declared: topic, schema (name, encoding, text), message encoding, metadata.
type Declared = (
    String,
    (String, String, String),
    &'static str,
    Vec<(String, String)>,
);

/// The path of file `index` of a series recorded to `base` (`run.mcap` -> `run_3.mcap`).
pub fn series_path(base: &Path, index: usize) -> PathBuf {
    let stem = base
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let name = match base.extension() {
        Some(ext) => format!("{stem}_{index}.{}", ext.to_string_lossy()),
        None => format!("{stem}_{index}"),
    };
    base.with_file_name(name)
}

/// The file being written and what it needs to be started again.
struct Current {
    w: McapWriter<BufWriter<File>>,
    schemas: HashMap<(String, String), u16>,
    channels: HashMap<u32, u16>,
    started: Instant,
}

struct Files<'a> {
    base: &'a Path,
    config: &'a RecordConfig,
    metadata: &'a [(String, String)],
    split: bool,
    index: usize,
    /// Bytes of the files already closed.
    closed: u64,
    declared: Vec<(u32, Declared)>,
}

impl Files<'_> {
    fn path(&self) -> PathBuf {
        if self.split {
            series_path(self.base, self.index)
        } else {
            self.base.to_path_buf()
        }
    }

    fn open(&self) -> Result<Current, RecordError> {
        let path = self.path();
        let file = File::create(&path).map_err(|source| RecordError::Create { path, source })?;
        let library = format!("limber {}", env!("CARGO_PKG_VERSION"));
        let mut w = McapWriter::new(
            BufWriter::new(file),
            &library,
            self.config.compression,
            self.config.chunk_size,
        )?;
        w.add_metadata("limber", self.metadata)?;
        let mut c = Current {
            w,
            schemas: HashMap::new(),
            channels: HashMap::new(),
            started: Instant::now(),
        };
        for (key, d) in &self.declared {
            declare(&mut c, *key, d)?;
        }
        Ok(c)
    }

    /// Ends `c`'s file; its size.
    fn close(c: Current) -> Result<u64, RecordError> {
        let out = c.w.finish()?;
        let file = out
            .into_inner()
            .map_err(|e| WriteError::Io(e.into_error()))?;
        file.sync_all().map_err(WriteError::Io)?;
        Ok(file.metadata().map_err(WriteError::Io)?.len())
    }

    fn full(&self, c: &Current) -> bool {
        self.config
            .split_bytes
            .is_some_and(|max| c.w.written() >= max)
            || self
                .config
                .split_time
                .is_some_and(|max| c.started.elapsed() >= max)
    }
}

fn declare(c: &mut Current, key: u32, d: &Declared) -> Result<(), RecordError> {
    let (topic, (name, encoding, data), message_encoding, metadata) = d;
    let id = match c.schemas.get(&(name.clone(), encoding.clone())) {
        Some(id) => *id,
        None => {
            let id = c.w.add_schema(name, encoding, data.as_bytes())?;
            c.schemas.insert((name.clone(), encoding.clone()), id);
            id
        }
    };
    let ch = c.w.add_channel(id, topic, message_encoding, metadata)?;
    c.channels.insert(key, ch);
    Ok(())
}

/// The writer thread: channels as they are declared, messages as they come, a new file
/// when the current one is full, until the queue closes; then the last summary.
pub(crate) fn write_all(
    base: &Path,
    rx: Receiver<Item>,
    config: &RecordConfig,
    counters: &Counters,
    metadata: &[(String, String)],
) -> Result<(), RecordError> {
    let mut files = Files {
        base,
        config,
        metadata,
        split: config.split_bytes.is_some() || config.split_time.is_some(),
        index: 0,
        closed: 0,
        declared: Vec::new(),
    };
    let mut c = files.open()?;
    for item in rx {
        match item {
            Item::Channel {
                key,
                topic,
                schema,
                encoding,
                metadata,
            } => {
                let d = (topic, schema, encoding, metadata);
                declare(&mut c, key, &d)?;
                files.declared.push((key, d));
                counters.channels.fetch_add(1, Ordering::Relaxed);
            }
            Item::Message {
                key,
                log_time,
                publish_time,
                data,
            } => {
                if let Some(ch) = c.channels.get(&key) {
                    c.w.write_message(*ch, log_time, publish_time, &data)?;
                    counters.messages.fetch_add(1, Ordering::Relaxed);
                    counters
                        .bytes
                        .store(files.closed + c.w.written(), Ordering::Relaxed);
                }
                if files.split && files.full(&c) {
                    files.index += 1;
                    let next = files.open()?;
                    files.closed += Files::close(core::mem::replace(&mut c, next))?;
                }
            }
        }
    }
    files.closed += Files::close(c)?;
    counters.bytes.store(files.closed, Ordering::Relaxed);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_series_is_numbered_beside_the_name_given() {
        assert_eq!(
            series_path(Path::new("/tmp/run.mcap"), 3),
            Path::new("/tmp/run_3.mcap")
        );
        assert_eq!(series_path(Path::new("run"), 0), Path::new("run_0"));
    }
}
