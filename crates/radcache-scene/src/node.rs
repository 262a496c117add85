//! The node hierarchy: local transforms, parent links and the traversal order of the scene.
//!
//! The glTF spec requires disjoint strict trees; a node with two parents, a cycle, or a root that
//! is also a child is an error naming the node. Only nodes reachable from the chosen scene's roots
//! take part in rendering ([`Node::in_scene`]). Traversal order is depth-first pre-order over the
//! roots in order, children in order: parents come before children, which is what world-transform
//! evaluation needs and what "first camera" means.

use glam::{Mat4, Quat, Vec3};

use crate::error::{label, Error, Result, WarningKind, Warnings};
use crate::math::Trs;
use crate::resources::Source;

/// A node's local transform as written in the file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LocalTransform {
    /// Translation/rotation/scale (may be animated).
    Trs(Trs),
    /// A 4×4 matrix (never animated; an animated matrix node is converted to TRS on load).
    Matrix(Mat4),
}

impl LocalTransform {
    /// The local-from-child matrix.
    pub fn matrix(&self) -> Mat4 {
        match self {
            LocalTransform::Trs(t) => t.matrix(),
            LocalTransform::Matrix(m) => *m,
        }
    }
}

/// A scene node.
#[derive(Clone, Debug, PartialEq)]
pub struct Node {
    /// Node name.
    pub name: Option<String>,
    /// Parent node, if any.
    pub parent: Option<usize>,
    /// Child nodes in order.
    pub children: Vec<usize>,
    /// Rest-pose local transform.
    pub local: LocalTransform,
    /// Mesh index, if the node instances a mesh.
    pub mesh: Option<usize>,
    /// glTF camera index, if the node carries a camera.
    pub camera: Option<usize>,
    /// Light index (into `Scene::lights`), if the node carries a punctual light.
    pub light: Option<usize>,
    /// Whether the node is reachable from the chosen scene's roots.
    pub in_scene: bool,
}

impl Node {
    /// Label for messages, e.g. `node 3 "camera"`.
    pub fn label(&self, index: usize) -> String {
        label("node", index, self.name.as_deref())
    }
}

/// Reads all nodes with checked transforms; `animated[i]` marks TRS-animated nodes.
pub(crate) fn load_nodes(
    src: &Source,
    animated: &[bool],
    warnings: &mut Warnings,
) -> Result<Vec<Node>> {
    let mut nodes = Vec::new();
    for n in src.doc.nodes() {
        let i = n.index();
        let node_label = label("node", i, n.name());
        let invalid = |reason: &str| Error::Invalid {
            path: src.path(),
            element: node_label.clone(),
            reason: reason.to_string(),
        };
        let local = match n.transform() {
            gltf::scene::Transform::Matrix { matrix } => {
                let m = Mat4::from_cols_array_2d(&matrix);
                if !m.is_finite() {
                    return Err(invalid("non-finite matrix"));
                }
                if animated.get(i).copied().unwrap_or(false) {
                    let (scale, rotation, translation) = m.to_scale_rotation_translation();
                    let msg = format!(
                        "{}: {node_label}: animated node uses a matrix; decomposed to TRS",
                        src.path.display()
                    );
                    warnings.push(WarningKind::MatrixNodeAnimated, 1, msg);
                    LocalTransform::Trs(Trs {
                        translation,
                        rotation: rotation.normalize(),
                        scale,
                    })
                } else {
                    LocalTransform::Matrix(m)
                }
            }
            gltf::scene::Transform::Decomposed {
                translation,
                rotation,
                scale,
            } => {
                let (t, r, s) = (
                    Vec3::from(translation),
                    Quat::from_array(rotation),
                    Vec3::from(scale),
                );
                if !t.is_finite() || !r.is_finite() || !s.is_finite() {
                    return Err(invalid("non-finite translation, rotation or scale"));
                }
                if r.length_squared() < 1e-12 {
                    return Err(invalid("zero-length rotation quaternion"));
                }
                LocalTransform::Trs(Trs {
                    translation: t,
                    rotation: r.normalize(),
                    scale: s,
                })
            }
        };
        if n.skin().is_some() {
            let msg = format!(
                "{}: {node_label}: skin ignored (rest pose used)",
                src.path.display()
            );
            warnings.push(WarningKind::SkinOrMorphIgnored, 1, msg);
        }
        nodes.push(Node {
            name: n.name().map(str::to_string),
            parent: None,
            children: n.children().map(|c| c.index()).collect(),
            local,
            mesh: n.mesh().map(|m| m.index()),
            camera: n.camera().map(|c| c.index()),
            light: n.light().map(|l| l.index()),
            in_scene: false,
        });
    }
    link_parents(src, &mut nodes)?;
    Ok(nodes)
}

fn link_parents(src: &Source, nodes: &mut [Node]) -> Result<()> {
    for p in 0..nodes.len() {
        for k in 0..nodes[p].children.len() {
            let c = nodes[p].children[k];
            let reason = if c == p {
                Some("is its own child".to_string())
            } else {
                nodes[c]
                    .parent
                    .map(|other| format!("has two parents (nodes {other} and {p})"))
            };
            if let Some(reason) = reason {
                return Err(Error::Invalid {
                    path: src.path(),
                    element: nodes[c].label(c),
                    reason,
                });
            }
            nodes[c].parent = Some(p);
        }
    }
    Ok(())
}

/// Marks the nodes reachable from `roots` and returns them in traversal order.
pub(crate) fn traversal_order(
    src: &Source,
    nodes: &mut [Node],
    roots: &[usize],
) -> Result<Vec<usize>> {
    let mut order = Vec::new();
    let mut stack: Vec<usize> = roots.iter().rev().copied().collect();
    for &r in roots {
        if let Some(p) = nodes.get(r).and_then(|n| n.parent) {
            return Err(Error::Invalid {
                path: src.path(),
                element: nodes[r].label(r),
                reason: format!("is a scene root but also a child of node {p}"),
            });
        }
    }
    while let Some(n) = stack.pop() {
        let Some(node) = nodes.get_mut(n) else {
            continue;
        };
        if node.in_scene {
            // With single parents this only happens for a cycle or a repeated root.
            return Err(Error::Invalid {
                path: src.path(),
                element: node.label(n),
                reason: "is reached twice (cycle in the hierarchy or repeated scene root)".into(),
            });
        }
        node.in_scene = true;
        order.push(n);
        stack.extend(node.children.iter().rev().copied());
    }
    Ok(order)
}
