//! `limber record --info`: what a file holds (channels, counts, time span).

use std::collections::BTreeMap;
use std::fs::File;
use std::path::Path;

use crate::mcap::{Channel, McapReader, ReadError, Record};

/// One channel of a file, with its message count and time span.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ChannelInfo {
    /// The channel.
    pub channel: Channel,
    /// Its schema's name ("" without one).
    pub schema: String,
    /// Its messages.
    pub messages: u64,
    /// The log time of its first and last message (ns since the Unix epoch).
    pub span: Option<(u64, u64)>,
}

/// What a file holds.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Info {
    /// Every channel, in the order of their ids.
    pub channels: Vec<ChannelInfo>,
    /// Every metadata record (name, entries).
    pub metadata: Vec<(String, Vec<(String, String)>)>,
    /// Messages in all.
    pub messages: u64,
    /// The first and last log time (ns since the Unix epoch).
    pub span: Option<(u64, u64)>,
}

/// Summarising a file failed.
#[derive(Debug, thiserror::Error)]
pub enum InfoError {
    /// The file could not be opened.
    #[error("cannot open {path}: {source}")]
    Open {
        /// The file.
        path: String,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// The file is not a readable MCAP file.
    #[error("{path}: {source}")]
    Read {
        /// The file.
        path: String,
        /// Why.
        #[source]
        source: ReadError,
    },
}

fn widen(span: &mut Option<(u64, u64)>, t: u64) {
    *span = Some(match *span {
        Some((a, b)) => (a.min(t), b.max(t)),
        None => (t, t),
    });
}

/// Reads `path` through and summarises it.
pub fn info(path: &Path) -> Result<Info, InfoError> {
    let shown = path.display().to_string();
    let file = File::open(path).map_err(|source| InfoError::Open {
        path: shown.clone(),
        source,
    })?;
    let read_err = |source| InfoError::Read {
        path: shown.clone(),
        source,
    };
    let mut r = McapReader::new(file).map_err(read_err)?;
    let mut schemas: BTreeMap<u16, String> = BTreeMap::new();
    let mut channels: BTreeMap<u16, ChannelInfo> = BTreeMap::new();
    let mut info = Info::default();
    while let Some(rec) = r.next_record().map_err(read_err)? {
        match rec {
            Record::Schema(s) => {
                schemas.insert(s.id, s.name);
            }
            Record::Channel(c) => {
                let schema = schemas.get(&c.schema_id).cloned().unwrap_or_default();
                channels.entry(c.id).or_insert(ChannelInfo {
                    channel: c,
                    schema,
                    messages: 0,
                    span: None,
                });
            }
            Record::Message {
                channel, log_time, ..
            } => {
                info.messages += 1;
                widen(&mut info.span, log_time);
                if let Some(c) = channels.get_mut(&channel) {
                    c.messages += 1;
                    widen(&mut c.span, log_time);
                }
            }
            Record::Metadata { name, entries } => info.metadata.push((name, entries)),
        }
    }
    info.channels = channels.into_values().collect();
    Ok(info)
}

impl core::fmt::Display for Info {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let secs = |s: Option<(u64, u64)>| s.map_or(0.0, |(a, b)| (b - a) as f64 / 1e9);
        writeln!(
            f,
            "messages: {} on {} channels over {:.3} s",
            self.messages,
            self.channels.len(),
            secs(self.span)
        )?;
        if let Some((a, _)) = self.span {
            writeln!(
                f,
                "start: {}.{:09} (s since the Unix epoch)",
                a / 1_000_000_000,
                a % 1_000_000_000
            )?;
        }
        for (name, entries) in &self.metadata {
            let e: Vec<String> = entries.iter().map(|(k, v)| format!("{k}={v}")).collect();
            writeln!(f, "metadata {name}: {}", e.join(" "))?;
        }
        writeln!(f, "channels:")?;
        for c in &self.channels {
            writeln!(
                f,
                "  {:<40} {:>8} msgs {:>9.3} s  {} ({})",
                c.channel.topic,
                c.messages,
                secs(c.span),
                c.schema,
                c.channel.message_encoding
            )?;
        }
        Ok(())
    }
}
