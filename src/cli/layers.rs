//! `kapaint layers`: a project's layer stack as CSV.

use std::fmt::Write as _;
use std::path::PathBuf;

use super::CliError;
use crate::model::layers::LayerStack;
use crate::model::texel::Channel;

/// List a project's layers as CSV (index 0 the bottom layer).
#[derive(Debug, clap::Args)]
pub struct LayersArgs {
    /// Project file.
    file: PathBuf,
}

impl LayersArgs {
    /// Runs the command; returns what it prints.
    ///
    /// # Errors
    /// A project that does not load.
    pub fn run(self) -> Result<String, CliError> {
        let doc = super::open_project(&self.file)?;
        Ok(layers_csv(doc.stack()))
    }
}

/// Quotes a CSV field when it needs it.
fn field(text: &str) -> String {
    if text.contains([',', '"', '\n']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_string()
    }
}

/// The CSV: header `index,kind,name,visible,opacity,kd_blend,ks_blend,n_blend,mask,bytes,id`, a
/// row per layer bottom first. The index of a layer in a group is its path (`1.0` is the
/// bottom layer of the group at index 1); `mask` is `none`, `on`, `off` or `inverted`;
/// `bytes` is the memory its tiles and mask hold; `id` is the layer's id (kept through moves
/// and saves; scripts select by it with `SelectLayer((id: N))`). A disabled channel's blend is
/// `off`.
pub fn layers_csv(stack: &LayerStack) -> String {
    let mut out =
        String::from("index,kind,name,visible,opacity,kd_blend,ks_blend,n_blend,mask,bytes,id\n");
    for (path, layer) in stack.walk() {
        let p = &layer.props;
        let index: Vec<String> = path.iter().map(ToString::to_string).collect();
        let blend = |c: Channel| {
            let b = p.channel(c);
            if b.enabled {
                b.mode.name(c).to_lowercase()
            } else {
                "off".into()
            }
        };
        let mask = match &layer.mask {
            None => "none",
            Some(m) if !m.enabled => "off",
            Some(m) if m.inverted => "inverted",
            Some(_) => "on",
        };
        let _ = writeln!(
            out,
            "{},{},{},{},{},{},{},{},{},{},{}",
            index.join("."),
            layer.kind_name(),
            field(&p.name),
            p.visible,
            p.opacity,
            blend(Channel::Kd),
            blend(Channel::Ks),
            blend(Channel::N),
            mask,
            layer.heap_bytes(),
            p.id
        );
    }
    out
}
