//! Clustered PCA of the receivers' transport (Sedláček 2019, 3.2.4): the receivers are
//! split into clusters by halving the scene's box along its widest axis, and each
//! cluster's transport matrix A (a row per receiver, a column per coefficient of the
//! probes that support any of them) is replaced by its truncated SVD, A ≈ U_k (Σ V^T)_k.
//! Per frame, each cluster's basis vector is b = (Σ V^T)_k λ (the probes' coefficients
//! stacked), and a receiver's irradiance is its row of U_k times b: k multiply-adds for
//! a receiver instead of one per probe and coefficient.
//!
//! A leaf is kept when it holds at most `max_receivers` and its projection error, the
//! thesis's 1 − √(Σ_{i≤k} σ_i / Σ σ_i), is below `max_error` with at most `max_basis`
//! vectors (the thesis's 1024, 0.005 and 32). The reconstruction's own error, the
//! relative Frobenius norm ‖A − A_k‖_F / ‖A‖_F = √(Σ_{i>k} σ_i² / Σ σ_i²), is reported
//! beside it: bounding that by 0.005 instead split the built-in box's 11,572 receivers
//! into 507 clusters whose matrices outweighed the transport they compress.

use faer::Mat;
use glam::Vec3;

use super::receivers::Receiver;
use super::transport::Transport;
use crate::progress::Progress;
use crate::scene::Aabb;

/// How the receivers are clustered.
#[derive(Clone, Copy, Debug)]
pub struct ClusterSettings {
    pub max_receivers: usize,
    pub max_error: f64,
    pub max_basis: usize,
}

/// The thesis's bounds (the bake's own error bound is looser: `BakeSettings::pca_error`).
impl Default for ClusterSettings {
    fn default() -> Self {
        Self {
            max_receivers: 1024,
            max_error: 0.005,
            max_basis: 32,
        }
    }
}

/// Clusters this small are not split further whatever their error: their matrices are
/// kept at `max_basis` vectors.
const MIN_SPLIT: usize = 32;

/// One cluster.
#[derive(Clone, Debug)]
pub struct Cluster {
    /// The probes supporting any of its receivers, in the order of the matrix's columns
    /// (each (order + 1)² wide).
    pub probes: Vec<u32>,
    /// The basis count k.
    pub basis: usize,
    /// (Σ V^T)_k, k rows of `probes.len()` · (order + 1)² columns, row-major.
    pub projection: Vec<f32>,
    /// The projection error (the thesis's measure).
    pub error: f64,
    /// The box of its receivers' positions (the level of detail's distance, 4.2.2).
    pub bounds: Aabb,
}

/// The clusters of every receiver.
#[derive(Clone, Debug)]
pub struct Clusters {
    pub list: Vec<Cluster>,
    /// Per receiver, its cluster.
    pub cluster_of: Vec<u32>,
    /// Per receiver, its row of U_k, at `offsets[r]..offsets[r] + k`.
    pub offsets: Vec<u32>,
    pub coordinates: Vec<f32>,
    /// Σ over the clusters of ‖A − A_k‖²_F and of ‖A‖²_F: the whole transport's relative
    /// error is the square root of their ratio.
    pub residual: f64,
    pub energy: f64,
}

impl Clusters {
    pub fn build(
        receivers: &[Receiver],
        transport: &Transport,
        settings: &ClusterSettings,
    ) -> Self {
        let mut out = Self {
            list: Vec::new(),
            cluster_of: vec![0; receivers.len()],
            offsets: vec![0; receivers.len()],
            coordinates: Vec::new(),
            residual: 0.0,
            energy: 0.0,
        };
        let mut bounds = Aabb::EMPTY;
        for r in receivers {
            bounds.extend(r.position);
        }
        let progress = Progress::new("clustering receivers", receivers.len() as u64);
        let all: Vec<u32> = (0..receivers.len() as u32).collect();
        let mut stack = vec![(all, bounds)];
        while let Some((members, bounds)) = stack.pop() {
            let fits = members.len() <= settings.max_receivers;
            let leaf = if fits {
                let leaf = decompose(&members, transport, settings);
                let keep = leaf.cluster.error <= settings.max_error || members.len() <= MIN_SPLIT;
                keep.then_some(leaf)
            } else {
                None
            };
            match leaf {
                Some(mut leaf) => {
                    let c = out.list.len() as u32;
                    for &r in &members {
                        leaf.cluster.bounds.extend(receivers[r as usize].position);
                    }
                    for (row, &r) in members.iter().enumerate() {
                        out.cluster_of[r as usize] = c;
                        out.offsets[r as usize] = out.coordinates.len() as u32;
                        out.coordinates.extend_from_slice(
                            &leaf.u[row * leaf.cluster.basis..(row + 1) * leaf.cluster.basis],
                        );
                    }
                    out.residual += leaf.residual;
                    out.energy += leaf.energy;
                    out.list.push(leaf.cluster);
                    progress.set(out.cluster_of.len() as u64 - stack_members(&stack) as u64);
                }
                None => {
                    let (low, high) = split(&members, &bounds, receivers);
                    stack.push(low);
                    stack.push(high);
                }
            }
        }
        progress.finish();
        out
    }

    /// Adds `other`'s clusters, whose receivers follow this one's.
    pub fn append(&mut self, other: Clusters) {
        let (clusters, coordinates) = (self.list.len() as u32, self.coordinates.len() as u32);
        self.cluster_of
            .extend(other.cluster_of.iter().map(|c| c + clusters));
        self.offsets
            .extend(other.offsets.iter().map(|o| o + coordinates));
        self.coordinates.extend(other.coordinates);
        self.list.extend(other.list);
        self.residual += other.residual;
        self.energy += other.energy;
    }

    /// Receiver `r`'s irradiance from the probes' `lambda` (probes × (order + 1)²) and a
    /// sky of radiance `sky`, through its cluster.
    pub fn irradiance(&self, transport: &Transport, lambda: &[Vec3], sky: Vec3, r: usize) -> Vec3 {
        let n = super::sh::coefficient_count(transport.order);
        let cluster = &self.list[self.cluster_of[r] as usize];
        let width = cluster.probes.len() * n;
        let u = &self.coordinates[self.offsets[r] as usize..][..cluster.basis];
        let mut e = sky * transport.sky[r];
        for (i, u) in u.iter().enumerate() {
            let row = &cluster.projection[i * width..(i + 1) * width];
            let mut b = Vec3::ZERO;
            for (p, &probe) in cluster.probes.iter().enumerate() {
                let l = &lambda[probe as usize * n..(probe as usize + 1) * n];
                for (a, l) in row[p * n..(p + 1) * n].iter().zip(l) {
                    b += *l * *a;
                }
            }
            e += b * *u;
        }
        e
    }

    /// The memory of the clusters' matrices and the receivers' coordinates, in bytes.
    pub fn bytes(&self) -> (usize, usize) {
        let matrices: usize = self
            .list
            .iter()
            .map(|c| c.projection.len() * 4 + c.probes.len() * 4)
            .sum();
        (
            matrices,
            self.coordinates.len() * 4 + self.offsets.len() * 8,
        )
    }
}

/// The receivers still waiting on the stack.
fn stack_members(stack: &[(Vec<u32>, Aabb)]) -> usize {
    stack.iter().map(|(m, _)| m.len()).sum()
}

/// Halves `bounds` along its widest axis (at the median of the members' positions along
/// it where one half would be empty).
fn split(
    members: &[u32],
    bounds: &Aabb,
    receivers: &[Receiver],
) -> ((Vec<u32>, Aabb), (Vec<u32>, Aabb)) {
    let size = bounds.size();
    let axis = if size.x >= size.y && size.x >= size.z {
        0
    } else if size.y >= size.z {
        1
    } else {
        2
    };
    let mut cut = bounds.center()[axis];
    let below = |cut: f32| {
        members
            .iter()
            .filter(|&&r| receivers[r as usize].position[axis] < cut)
            .count()
    };
    let count = below(cut);
    if count == 0 || count == members.len() {
        let mut along: Vec<f32> = members
            .iter()
            .map(|&r| receivers[r as usize].position[axis])
            .collect();
        along.sort_by(f32::total_cmp);
        cut = along[along.len() / 2];
    }
    let (mut low, mut high) = (Vec::new(), Vec::new());
    for &r in members {
        if receivers[r as usize].position[axis] < cut {
            low.push(r);
        } else {
            high.push(r);
        }
    }
    if low.is_empty() {
        // Every member at one position along the axis: split the list itself.
        low = high.split_off(high.len() / 2);
    }
    let halves = [&low, &high].map(|m| {
        let mut b = Aabb::EMPTY;
        for &r in m.iter() {
            b.extend(receivers[r as usize].position);
        }
        b
    });
    ((low, halves[0]), (high, halves[1]))
}

/// A cluster's decomposition, with its receivers' rows of U_k.
struct Leaf {
    cluster: Cluster,
    u: Vec<f32>,
    residual: f64,
    energy: f64,
}

fn decompose(members: &[u32], transport: &Transport, settings: &ClusterSettings) -> Leaf {
    let n = super::sh::coefficient_count(transport.order);
    let mut probes: Vec<u32> = members
        .iter()
        .flat_map(|&r| {
            let range =
                transport.offsets[r as usize] as usize..transport.offsets[r as usize + 1] as usize;
            transport.probes[range].iter().copied()
        })
        .collect();
    probes.sort_unstable();
    probes.dedup();
    let column = |probe: u32| probes.binary_search(&probe).expect("a member's probe") * n;
    let width = probes.len() * n;
    let mut a = Mat::<f64>::zeros(members.len(), width);
    for (row, &r) in members.iter().enumerate() {
        for k in transport.offsets[r as usize] as usize..transport.offsets[r as usize + 1] as usize
        {
            let c = column(transport.probes[k]);
            for j in 0..n {
                a[(row, c + j)] = transport.alpha[k * n + j] as f64;
            }
        }
    }
    let empty = |error: f64| Leaf {
        cluster: Cluster {
            probes: probes.clone(),
            basis: 0,
            projection: Vec::new(),
            error,
            bounds: Aabb::EMPTY,
        },
        u: Vec::new(),
        residual: 0.0,
        energy: 0.0,
    };
    if width == 0 {
        return empty(0.0);
    }
    let Ok(svd) = a.thin_svd() else {
        // No convergence: an error above any bound, so the cluster is split.
        return empty(f64::INFINITY);
    };
    let s = svd.S().column_vector();
    let sigma: Vec<f64> = (0..s.nrows()).map(|i| s[i]).collect();
    let energy: f64 = sigma.iter().map(|s| s * s).sum();
    if energy == 0.0 {
        return empty(0.0);
    }
    // The fewest vectors meeting the bound, at most max_basis.
    let sum: f64 = sigma.iter().sum();
    let error = |k: usize| 1.0 - (sigma[..k].iter().sum::<f64>() / sum).sqrt();
    let mut k = 0;
    while k < sigma.len().min(settings.max_basis) && error(k) > settings.max_error {
        k += 1;
    }
    let tail: f64 = sigma[k..].iter().map(|s| s * s).sum();
    let (u, v) = (svd.U(), svd.V());
    let mut projection = vec![0.0f32; k * width];
    for i in 0..k {
        for c in 0..width {
            projection[i * width + c] = (sigma[i] * v[(c, i)]) as f32;
        }
    }
    let mut rows = vec![0.0f32; members.len() * k];
    for row in 0..members.len() {
        for i in 0..k {
            rows[row * k + i] = u[(row, i)] as f32;
        }
    }
    Leaf {
        cluster: Cluster {
            probes,
            basis: k,
            projection,
            error: error(k),
            bounds: Aabb::EMPTY,
        },
        u: rows,
        residual: tail,
        energy,
    }
}
