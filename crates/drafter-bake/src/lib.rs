//! `bake(&Scene, &BakeConfig)`: the stage order of a bake, its timings and report.
//!
//! Stages, in order (each a function of plain data in its own crate):
//! 1. `segment` — parts (drafter-segment);
//! 2. `bounds` — per part, an oriented box of its world-space vertices, the projector derived from
//!    it and the gradient parameters, then per-part overrides from the config (drafter-bounds);
//! 3. `write` — the extended glTF (drafter-format).
//!
//! Invariant: this is the only crate that knows the order. The output bytes depend only on the
//! scene and the config, never on timings or the thread count (parts are processed in parallel and
//! collected in part order).

mod config;

use std::time::Instant;

use drafter_bounds::{Obb, ObbOptions, Projector, oriented_box};
use drafter_core::{Diagnostic, PartId, Scene};
use drafter_format::{
    BakeOutput, BoxRecord, FORMAT_VERSION, GENERATOR, GradientRecord, InputInfo, PartRecord, ProjectorRecord,
    RootExtension, Written,
};
use drafter_segment::{MeshLabels, Parts};
use glam::DVec3;
use rayon::prelude::*;
use serde::Serialize;

pub use config::{BakeConfig, PartOverride, PartSelector, STYLES};

/// Why a bake failed.
#[derive(Debug, thiserror::Error)]
pub enum BakeError {
    /// The config (file or options) is invalid: the user's fault.
    #[error("config: {0}")]
    Config(String),
    /// The scene cannot be baked (e.g. it has no triangles): the input's fault.
    #[error("{0}")]
    Input(String),
    /// A stage failed where it should not: a bug.
    #[error("internal error in stage {stage}: {message}")]
    Internal { stage: &'static str, message: String },
}

/// A finished bake: the file's bytes and the report.
#[derive(Debug)]
pub struct Baked {
    pub written: Written,
    pub report: BakeReport,
}

/// What `--report FILE.json` contains.
#[derive(Clone, Debug, Serialize)]
pub struct BakeReport {
    pub input: InputInfo,
    pub triangles: usize,
    pub parts: Vec<PartReport>,
    pub stages: Vec<StageTiming>,
    /// Bytes of the written file(s).
    pub output_bytes: u64,
    pub diagnostics: Vec<Diagnostic>,
}

#[derive(Clone, Debug, Serialize)]
pub struct PartReport {
    pub id: u32,
    pub name: String,
    pub triangles: u32,
    pub obb: ObbReport,
    pub projector: ProjectorReport,
    pub gradient: GradientRecord,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub style: Option<String>,
}

#[derive(Clone, Debug, Serialize)]
pub struct ObbReport {
    pub center: [f64; 3],
    pub axes: [[f64; 3]; 3],
    pub half_extents: [f64; 3],
    pub volume: f64,
    pub method: String,
}

#[derive(Clone, Debug, Serialize)]
pub struct ProjectorReport {
    pub anchor: [f64; 3],
    pub direction: [f64; 3],
    pub scale: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct StageTiming {
    pub name: &'static str,
    pub ms: f64,
}

/// Runs every stage on `scene` and writes the extended glTF in memory.
pub fn bake(scene: &Scene, config: &BakeConfig) -> Result<Baked, BakeError> {
    if scene.instanced_triangle_count() == 0 {
        return Err(BakeError::Input("the scene has no triangles to bake".into()));
    }
    let mut stages = Vec::new();
    let mut timed =
        |name: &'static str, start: Instant| stages.push(StageTiming { name, ms: start.elapsed().as_secs_f64() * 1e3 });

    let start = Instant::now();
    let (parts, mut diagnostics) = drafter_segment::segment(scene, &config.segment);
    timed("segment", start);

    let start = Instant::now();
    let records = bound_parts(scene, &parts, config)?;
    timed("bounds", start);

    let start = Instant::now();
    let bounds = scene.world_bounds();
    let center = if bounds.is_empty() { DVec3::ZERO } else { (bounds.min + bounds.max) * 0.5 };
    let root = RootExtension {
        version: FORMAT_VERSION.to_owned(),
        generator: GENERATOR.to_owned(),
        input: config.input.clone(),
        settings: settings_echo(config),
        scene_center: center.to_array(),
        part_count: parts.len() as u32,
    };
    let instance_parts: Vec<Vec<PartRecord>> = parts
        .instances
        .iter()
        .map(|ip| records[ip.first_part.index()..ip.first_part.index() + ip.part_count as usize].to_vec())
        .collect();
    let mut mesh_labels: Vec<Option<Vec<u32>>> = vec![None; scene.meshes.len()];
    for (inst, ip) in scene.instances.iter().zip(&parts.instances) {
        if let MeshLabels::PerTriangle(table) = &ip.labels {
            mesh_labels[inst.mesh.index()].get_or_insert_with(|| table.labels().to_vec());
        }
    }
    let output = BakeOutput { scene, root, instance_parts, mesh_labels };
    let written = drafter_format::write(&output, &config.container)
        .map_err(|e| BakeError::Internal { stage: "write", message: e.to_string() })?;
    timed("write", start);

    let output_bytes = (written.main.len() + written.bin.as_ref().map_or(0, Vec::len)) as u64;
    diagnostics.sort_by_key(|d| d.kind);
    let report = BakeReport {
        input: config.input.clone(),
        triangles: scene.instanced_triangle_count(),
        parts: records.iter().map(part_report).collect(),
        stages,
        output_bytes,
        diagnostics,
    };
    Ok(Baked { written, report })
}

/// The options that shaped the file (never the thread count: output is identical at any).
fn settings_echo(config: &BakeConfig) -> serde_json::Value {
    serde_json::json!({
        "segment": {"mode": config.segment.mode, "regionAngleDeg": config.segment.region_angle_deg},
        "obb": {"method": config.obb.method.name()},
        "gradient": {"q": config.gradient.q, "f": config.gradient.f, "p": config.gradient.p, "transfer": config.transfer},
        "partOverrides": config.overrides.len(),
    })
}

/// Box, projector and gradient of every part, in part order; overrides applied.
fn bound_parts(scene: &Scene, parts: &Parts, config: &BakeConfig) -> Result<Vec<PartRecord>, BakeError> {
    // Resolve overrides to part ids first, so a selector that matches nothing is reported.
    let mut per_part: Vec<Vec<&PartOverride>> = vec![Vec::new(); parts.len()];
    for o in &config.overrides {
        let matched: Vec<usize> = if match &o.selector {
            PartSelector::Id(id) => (*id as usize) < parts.len(),
            PartSelector::Name(_) => true,
        } {
            {
                (0..parts.len())
                    .filter(|&p| match &o.selector {
                        PartSelector::Id(id) => p == *id as usize,
                        PartSelector::Name(n) => &parts.parts[p].name == n,
                    })
                    .collect()
            }
        } else {
            Default::default()
        };
        if matched.is_empty() {
            let what = match &o.selector {
                PartSelector::Id(id) => format!("id {id} (the scene has {} parts)", parts.len()),
                PartSelector::Name(n) => format!("name {n:?}"),
            };
            return Err(BakeError::Config(format!("part override with {what} matches no part")));
        }
        for p in matched {
            per_part[p].push(o);
        }
    }
    let bounds = scene.world_bounds();
    let center = if bounds.is_empty() { DVec3::ZERO } else { (bounds.min + bounds.max) * 0.5 };
    (0..parts.len())
        .into_par_iter()
        .map(|p| {
            let part = &parts.parts[p];
            let overrides = &per_part[p];
            let method = overrides.iter().rev().find_map(|o| o.method).unwrap_or(config.obb.method);
            let points = part_points(scene, parts, PartId::from(p));
            let obb = oriented_box(&points, &ObbOptions { method, ..config.obb }).map_err(|e| BakeError::Internal {
                stage: "bounds",
                message: format!("part {p} ({}): {e}", part.name),
            })?;
            let mut projector = Projector::from_obb(&obb, center);
            let mut gradient = config.gradient;
            let mut transfer = config.transfer;
            let mut style = None;
            for o in overrides {
                if let Some(d) = o.direction {
                    projector.direction = DVec3::from(d).normalize();
                }
                if let Some(a) = o.anchor {
                    projector.anchor = DVec3::from(a);
                }
                if let Some(s) = o.scale {
                    projector.scale = s;
                }
                gradient = o.gradient(&gradient);
                transfer = o.transfer.unwrap_or(transfer);
                style = o.style.clone().or(style);
            }
            Ok(PartRecord {
                id: p as u32,
                name: part.name.clone(),
                triangles: part.triangles,
                obb: box_record(&obb),
                projector: ProjectorRecord {
                    anchor: projector.anchor.to_array(),
                    direction: projector.direction.to_array(),
                    scale: projector.scale,
                    matrix: projector.matrix().to_cols_array(),
                },
                gradient: GradientRecord {
                    q: f64::from(gradient.q),
                    f: f64::from(gradient.f),
                    p: f64::from(gradient.p),
                    transfer: serde_json::to_value(transfer)
                        .ok()
                        .and_then(|v| v.as_str().map(str::to_owned))
                        .unwrap_or_else(|| "identity".into()),
                },
                style,
            })
        })
        .collect()
}

/// World-space positions of the vertices used by `part` (each mesh vertex once).
pub fn part_points(scene: &Scene, parts: &Parts, part: PartId) -> Vec<DVec3> {
    let info = parts.part(part);
    let instance = &scene.instances[info.instance.index()];
    let mesh = scene.mesh(instance.mesh);
    let mut seen = vec![false; mesh.positions.len()];
    let mut points = Vec::new();
    for t in parts.triangles_of(part) {
        for v in mesh.triangles[t as usize] {
            if !std::mem::replace(&mut seen[v as usize], true) {
                points.push(instance.world_from_object.transform_point3(mesh.positions[v as usize].as_dvec3()));
            }
        }
    }
    points
}

fn box_record(obb: &Obb) -> BoxRecord {
    BoxRecord {
        center: obb.center.to_array(),
        axes: obb.axes.map(|a| a.to_array()),
        half_extents: obb.half_extents.to_array(),
        volume: obb.volume,
        method: obb.method.name().to_owned(),
    }
}

fn part_report(r: &PartRecord) -> PartReport {
    PartReport {
        id: r.id,
        name: r.name.clone(),
        triangles: r.triangles,
        obb: ObbReport {
            center: r.obb.center,
            axes: r.obb.axes,
            half_extents: r.obb.half_extents,
            volume: r.obb.volume,
            method: r.obb.method.clone(),
        },
        projector: ProjectorReport {
            anchor: r.projector.anchor,
            direction: r.projector.direction,
            scale: r.projector.scale,
        },
        gradient: r.gradient.clone(),
        style: r.style.clone(),
    }
}
