//! The output of segmentation: parts, and the map from each instance's triangles to parts.

use std::sync::Arc;

use drafter_core::{InstanceId, MeshId, PartId};
use serde::Serialize;

/// One part: a set of triangles of one instance.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Part {
    /// The instance's name, with `#label` appended when its mesh splits into several parts.
    pub name: String,
    /// The instance the part belongs to.
    pub instance: InstanceId,
    /// The instance's mesh.
    pub mesh: MeshId,
    /// The part's label within its mesh's segmentation (`0..part_count` of the instance).
    pub label: u32,
    /// Number of triangles.
    pub triangles: u32,
}

/// A mesh's segmentation, shared by every instance of the mesh: a label per triangle, plus the
/// triangles of each label in increasing order.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LabelTable {
    labels: Vec<u32>,
    offsets: Vec<u32>,
    by_label: Vec<u32>,
}

impl LabelTable {
    /// Builds the table from one label per triangle; labels must be dense (`0..count`).
    pub(crate) fn new(labels: Vec<u32>, count: u32) -> Self {
        let mut offsets = vec![0u32; count as usize + 1];
        for &l in &labels {
            offsets[l as usize + 1] += 1;
        }
        for i in 0..count as usize {
            offsets[i + 1] += offsets[i];
        }
        let mut cursor = offsets.clone();
        let mut by_label = vec![0u32; labels.len()];
        for (t, &l) in labels.iter().enumerate() {
            by_label[cursor[l as usize] as usize] = t as u32;
            cursor[l as usize] += 1;
        }
        Self { labels, offsets, by_label }
    }

    /// Number of labels.
    pub fn label_count(&self) -> u32 {
        (self.offsets.len() - 1) as u32
    }

    /// Label of each triangle of the mesh.
    pub fn labels(&self) -> &[u32] {
        &self.labels
    }

    /// Label of triangle `t`.
    #[inline]
    pub fn label(&self, t: u32) -> u32 {
        self.labels[t as usize]
    }

    /// Triangles with label `label`, increasing.
    pub fn triangles(&self, label: u32) -> &[u32] {
        &self.by_label[self.offsets[label as usize] as usize..self.offsets[label as usize + 1] as usize]
    }
}

/// How an instance's triangles map to labels.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum MeshLabels {
    /// The whole mesh is one part (label 0).
    Whole,
    /// A label per triangle, shared (`Arc`) by all instances of the same mesh.
    PerTriangle(Arc<LabelTable>),
}

/// The parts of one instance: `first_part .. first_part + part_count`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct InstanceParts {
    pub first_part: PartId,
    pub part_count: u32,
    pub labels: MeshLabels,
}

impl InstanceParts {
    /// The part of triangle `t` of this instance's mesh.
    #[inline]
    pub fn part_of(&self, t: u32) -> PartId {
        match &self.labels {
            MeshLabels::Whole => self.first_part,
            MeshLabels::PerTriangle(table) => PartId(self.first_part.0 + table.label(t)),
        }
    }
}

/// The result of [`crate::segment`].
///
/// Invariant: parts are numbered by instance (in scene order), then by label; an instance's parts
/// are contiguous. Labels are numbered in order of their first triangle.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Parts {
    /// Every part; the index is the [`PartId`].
    pub parts: Vec<Part>,
    /// One entry per scene instance, same order as `Scene::instances`.
    pub instances: Vec<InstanceParts>,
}

impl Parts {
    pub fn len(&self) -> usize {
        self.parts.len()
    }

    pub fn is_empty(&self) -> bool {
        self.parts.is_empty()
    }

    pub fn part(&self, id: PartId) -> &Part {
        &self.parts[id.index()]
    }

    /// The part of triangle `triangle` (an index into its mesh's triangles) of `instance`.
    pub fn part_of(&self, instance: InstanceId, triangle: u32) -> PartId {
        self.instances[instance.index()].part_of(triangle)
    }

    /// The triangles (indices into the instance's mesh) of `part`, increasing.
    pub fn triangles_of(&self, part: PartId) -> PartTriangles<'_> {
        let p = &self.parts[part.index()];
        match &self.instances[p.instance.index()].labels {
            MeshLabels::Whole => PartTriangles::Range(0..p.triangles),
            MeshLabels::PerTriangle(table) => PartTriangles::List(table.triangles(p.label).iter()),
        }
    }
}

/// Iterator over the triangles of a part, see [`Parts::triangles_of`].
#[derive(Clone, Debug)]
pub enum PartTriangles<'a> {
    Range(std::ops::Range<u32>),
    List(std::slice::Iter<'a, u32>),
}

impl Iterator for PartTriangles<'_> {
    type Item = u32;

    #[inline]
    fn next(&mut self) -> Option<u32> {
        match self {
            Self::Range(r) => r.next(),
            Self::List(l) => l.next().copied(),
        }
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        match self {
            Self::Range(r) => r.size_hint(),
            Self::List(l) => l.size_hint(),
        }
    }
}

impl ExactSizeIterator for PartTriangles<'_> {}
