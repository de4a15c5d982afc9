//! Lines pass — the hook for baked edges (issue 6, item 3; not implemented yet).
//!
//! # Where it goes
//! Between the enhancement and display passes. Baked files do not carry edges yet (drafter-lines
//! will write creases, boundaries and part borders, plus the silhouette hierarchy, through
//! drafter-format). When they do, this pass will:
//! 1. read per-mesh edge lists (two vertex indices and a class per edge) from [`crate::Model`];
//! 2. find the current silhouettes (front/back facing change for this camera, from the baked
//!    hierarchy or a compute pass over all edges — whichever measures faster);
//! 3. draw every visible edge as a screen-space quad of a width in pixels (wgpu has no wide lines),
//!    joined without gaps, with a small depth offset towards the camera and a depth test against
//!    the G-buffer depth so lines sit in front of their own surfaces without fighting them;
//!    creases white, boundaries and part borders black, the outer outline heavier (Gooch et al.
//!    1999, §3.1);
//! 4. write into the enhancement target's outline/crease channels, so the display pass composites
//!    geometric and image-space lines the same way.
//!
//! Until then [`crate::RenderOptions::enhancements`] draws outlines, silhouettes and creases from
//! the G-buffer, and [`notice`] says so.

use crate::model::Model;

pub const LABEL: &str = "lines";

/// The line the renderer reports while edges are not baked: where outlines come from instead.
pub fn notice(_model: &Model) -> Option<&'static str> {
    Some("no baked edges in this file: outlines and creases come from the image-space enhancement pass")
}
