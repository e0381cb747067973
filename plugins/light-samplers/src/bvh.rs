//! `bvh`: lights picked by descending a bounding volume hierarchy over their
//! [`LightBounds`] (pbrt-v4 `BVHLightSampler`, section 12.6.3; Conty
//! Estevez and Kulla 2018).
//!
//! A node bounds its lights' positions (a box), the cone of their normals
//! (`theta_o`), the spread of their emission (`theta_e`), their power and
//! their sides. The tree is built by SAH over 12 buckets per axis with the
//! orientation cost `phi M_Omega K_r SA` (pbrt-v4's `EvaluateCost`), on two
//! threads above 16k lights; where the depth left only suffices for a
//! balanced tree it splits at the median, so no light's trail exceeds 64
//! levels.
//!
//! `sample` descends from the root, choosing each child in proportion to
//! its importance from the shading point: power over the clamped squared
//! distance, times `cos theta'`, and times `cos theta_i'` on a surface.
//! `pmf` follows the light's bit trail from the root and multiplies the
//! same choices. Near, bright lights facing the point get the shadow rays;
//! lights behind it or facing away get none. Where both children of a node
//! are out of reach, `sample` returns no light (the pmf then sums to less
//! than 1); a light whose bounds cannot reach the point has pmf 0 there.
//!
//! Lights without bounds (environments) are picked alongside the tree, each
//! with probability `1 / (n_infinite + 1)`, or `1 / n_infinite` where
//! nothing in the tree can reach the point. A light of zero power is never
//! picked.

use lumis_api::{
    Aabb, Light, LightBounds, LightSampleContext, LightSampler, PluginKind, PluginSpec,
    SampledLight, Vec3,
};
use rayon::join;

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::LightSampler,
    name: "bvh",
    source: lumis_api::source_file!(),
    doc: "descends a light BVH built by SAH over position and emission cones, at each node choosing a child by its importance from the shading point (Conty Estevez and Kulla 2018, pbrt-v4); lights without bounds (environments) picked alongside",
    params: &[],
};

/// A node of the tree. Interior nodes keep their first child right after
/// them (depth-first order) and the index of the second.
#[derive(Debug, Clone, Copy)]
struct Node {
    bounds: LightBounds,
    /// The second child's node index, or for a leaf its light's index.
    child_or_light: u32,
    is_leaf: bool,
}

/// Where the sampler keeps a scene light.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Slot {
    /// In the tree: bit `d` of `trail` says which child holds it at depth
    /// `d` (1 for the second).
    Tree { trail: u64 },
    /// Without bounds: picked alongside the tree.
    Infinite,
    /// Zero power: never picked.
    Dark,
}

#[derive(Debug, Clone)]
pub struct BvhLightSampler {
    nodes: Vec<Node>,
    slots: Vec<Slot>,
    /// Scene indices of the lights without bounds.
    infinite: Vec<u32>,
}

/// The largest `f32` below one: where a remapped `u` must stay.
const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

impl BvhLightSampler {
    pub fn new(lights: &[Box<dyn Light>]) -> Self {
        Self::from_bounds(lights.iter().map(|l| l.bounds()))
    }

    /// From each light's bounds (`None` for an infinite light).
    pub fn from_bounds(bounds: impl IntoIterator<Item = Option<LightBounds>>) -> Self {
        let mut slots = Vec::new();
        let mut infinite = Vec::new();
        let mut items = Vec::new();
        for (index, bounds) in bounds.into_iter().enumerate() {
            slots.push(match bounds {
                None => {
                    infinite.push(index as u32);
                    Slot::Infinite
                }
                Some(b) if b.phi > 0.0 && b.phi.is_finite() => {
                    items.push(Item {
                        index: index as u32,
                        centroid: b.bounds.center(),
                        bounds: b,
                    });
                    Slot::Dark
                }
                Some(_) => Slot::Dark,
            });
        }
        let nodes = if items.is_empty() {
            Vec::new()
        } else {
            build(&mut items, 0).0
        };
        let mut sampler = Self {
            nodes,
            slots,
            infinite,
        };
        sampler.record_trails();
        sampler
    }

    /// Gives each light in the tree the path from the root to its leaf.
    fn record_trails(&mut self) {
        if self.nodes.is_empty() {
            return;
        }
        let mut stack = vec![(0usize, 0u64, 0u32)];
        while let Some((node, trail, depth)) = stack.pop() {
            let n = self.nodes[node];
            if n.is_leaf {
                self.slots[n.child_or_light as usize] = Slot::Tree { trail };
            } else {
                stack.push((node + 1, trail, depth + 1));
                stack.push((n.child_or_light as usize, trail | 1 << depth, depth + 1));
            }
        }
    }

    /// The probability of picking among the infinite lights from `p`: all
    /// of it where the tree cannot reach `p`.
    fn p_infinite(&self, p: Vec3, n: Vec3) -> f32 {
        if self.infinite.is_empty() {
            return 0.0;
        }
        match self.nodes.first() {
            Some(root) if root.bounds.importance(p, n) > 0.0 => {
                self.infinite.len() as f32 / (self.infinite.len() + 1) as f32
            }
            _ => 1.0,
        }
    }

    /// The two children of interior node `node` and the probability of
    /// descending to the first one; `None` where neither reaches `p`.
    #[inline]
    fn children(&self, node: usize, p: Vec3, n: Vec3) -> Option<([usize; 2], f32)> {
        let second = self.nodes[node].child_or_light as usize;
        let c0 = self.nodes[node + 1].bounds.importance(p, n);
        let c1 = self.nodes[second].bounds.importance(p, n);
        let total = c0 + c1;
        (total > 0.0).then(|| ([node + 1, second], c0 / total))
    }

    /// The tree's light count (lights with bounds and power).
    pub fn tree_lights(&self) -> usize {
        self.nodes.len().div_ceil(2)
    }
}

impl LightSampler for BvhLightSampler {
    fn sample(&self, ctx: &LightSampleContext, u: f32) -> Option<SampledLight> {
        let (p, n) = (ctx.p(), ctx.ns);
        let p_infinite = self.p_infinite(p, n);
        if u < p_infinite {
            let count = self.infinite.len();
            let i = ((u / p_infinite * count as f32) as usize).min(count - 1);
            return Some(SampledLight {
                index: self.infinite[i],
                pmf: p_infinite / count as f32,
            });
        }
        let root = self.nodes.first()?;
        let mut u = ((u - p_infinite) / (1.0 - p_infinite)).min(ONE_MINUS_EPSILON);
        let mut pmf = 1.0 - p_infinite;
        let mut node = 0;
        if root.is_leaf && root.bounds.importance(p, n) <= 0.0 {
            return None;
        }
        while !self.nodes[node].is_leaf {
            let ([first, second], p_first) = self.children(node, p, n)?;
            if u < p_first {
                u = (u / p_first).min(ONE_MINUS_EPSILON);
                pmf *= p_first;
                node = first;
            } else {
                u = ((u - p_first) / (1.0 - p_first)).min(ONE_MINUS_EPSILON);
                pmf *= 1.0 - p_first;
                node = second;
            }
        }
        (pmf > 0.0).then(|| SampledLight {
            index: self.nodes[node].child_or_light,
            pmf,
        })
    }

    /// The product of the choices along the light's trail, as `sample`
    /// makes them.
    fn pmf(&self, ctx: &LightSampleContext, index: u32) -> f32 {
        let (p, n) = (ctx.p(), ctx.ns);
        let mut trail = match self.slots.get(index as usize) {
            Some(Slot::Tree { trail }) => *trail,
            Some(Slot::Infinite) => {
                return self.p_infinite(p, n) / self.infinite.len() as f32;
            }
            Some(Slot::Dark) | None => return 0.0,
        };
        let p_infinite = self.p_infinite(p, n);
        let mut pmf = 1.0 - p_infinite;
        let mut node = 0;
        if self.nodes[0].is_leaf && self.nodes[0].bounds.importance(p, n) <= 0.0 {
            return 0.0;
        }
        while !self.nodes[node].is_leaf {
            let Some(([first, second], p_first)) = self.children(node, p, n) else {
                return 0.0;
            };
            if trail & 1 == 0 {
                pmf *= p_first;
                node = first;
            } else {
                pmf *= 1.0 - p_first;
                node = second;
            }
            trail >>= 1;
        }
        pmf
    }
}

/// A light being sorted into the tree.
#[derive(Debug, Clone, Copy)]
struct Item {
    index: u32,
    centroid: Vec3,
    bounds: LightBounds,
}

/// Subtrees of at least this many lights are built on two threads.
const PARALLEL_MIN: usize = 16 * 1024;

/// SAH buckets per axis (pbrt-v4's twelve).
const BUCKETS: usize = 12;

/// The deepest a leaf may be: its trail has one bit per level.
const MAX_DEPTH: u32 = 64;

/// The subtree over `items` at depth `depth`, its nodes numbered from 0,
/// and its bounds.
fn build(items: &mut [Item], depth: u32) -> (Vec<Node>, LightBounds) {
    if items.len() < PARALLEL_MIN {
        let mut nodes = Vec::with_capacity(2 * items.len() - 1);
        let bounds = build_into(&mut nodes, items, depth);
        return (nodes, bounds);
    }
    let mid = split(items, depth);
    let (first, second) = items.split_at_mut(mid);
    let ((nodes0, b0), (nodes1, b1)) =
        join(|| build(first, depth + 1), || build(second, depth + 1));
    let bounds = b0.union(b1);
    let mut nodes = Vec::with_capacity(1 + nodes0.len() + nodes1.len());
    let second_index = 1 + nodes0.len();
    nodes.push(Node {
        bounds,
        child_or_light: second_index as u32,
        is_leaf: false,
    });
    for (subtree, offset) in [(nodes0, 1), (nodes1, second_index)] {
        nodes.extend(subtree.into_iter().map(|mut n| {
            if !n.is_leaf {
                n.child_or_light += offset as u32;
            }
            n
        }));
    }
    (nodes, bounds)
}

/// [`build`] on one thread, appending to `nodes`.
fn build_into(nodes: &mut Vec<Node>, items: &mut [Item], depth: u32) -> LightBounds {
    if let [item] = items {
        nodes.push(Node {
            bounds: item.bounds,
            child_or_light: item.index,
            is_leaf: true,
        });
        return item.bounds;
    }
    let mid = split(items, depth);
    let (first, second) = items.split_at_mut(mid);
    let node = nodes.len();
    nodes.push(Node {
        bounds: LightBounds::EMPTY,
        child_or_light: 0,
        is_leaf: false,
    });
    let b0 = build_into(nodes, first, depth + 1);
    let second_index = nodes.len();
    let b1 = build_into(nodes, second, depth + 1);
    let bounds = b0.union(b1);
    nodes[node] = Node {
        bounds,
        child_or_light: second_index as u32,
        is_leaf: false,
    };
    bounds
}

/// Reorders `items` (at least two) into the two children's and returns
/// where the second begins: the bucket boundary of least SAH cost, or the
/// median along the widest axis where no boundary separates the lights or
/// the depth left only just suffices for a balanced split.
fn split(items: &mut [Item], depth: u32) -> usize {
    let centroids = Aabb::of_points(items.iter().map(|i| i.centroid));
    let extent = centroids.diagonal();
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    let levels_needed = usize::BITS - (items.len() - 1).leading_zeros();
    if depth + levels_needed < MAX_DEPTH {
        if let Some((dim, bucket)) = cheapest_split(items, &centroids) {
            let mid = partition(items, |i| bucket_of(i.centroid, &centroids, dim) <= bucket);
            if mid > 0 && mid < items.len() {
                return mid;
            }
        }
    }
    let mid = items.len() / 2;
    items.select_nth_unstable_by(mid, |a, b| a.centroid[axis].total_cmp(&b.centroid[axis]));
    mid
}

/// Moves the items for which `below` holds to the front; returns their count.
fn partition(items: &mut [Item], below: impl Fn(&Item) -> bool) -> usize {
    let mut mid = 0;
    for i in 0..items.len() {
        if below(&items[i]) {
            items.swap(i, mid);
            mid += 1;
        }
    }
    mid
}

fn bucket_of(centroid: Vec3, centroids: &Aabb, dim: usize) -> usize {
    let t = (centroid[dim] - centroids.min[dim]) / (centroids.max[dim] - centroids.min[dim]);
    ((t * BUCKETS as f32) as usize).min(BUCKETS - 1)
}

/// The axis and last bucket below the split of least positive cost, over
/// the bucket boundaries of every axis the centroids spread along.
fn cheapest_split(items: &[Item], centroids: &Aabb) -> Option<(usize, usize)> {
    let all = items
        .iter()
        .fold(Aabb::EMPTY, |b, i| b.union(i.bounds.bounds));
    let mut best: Option<(f32, usize, usize)> = None;
    for dim in 0..3 {
        if centroids.max[dim] <= centroids.min[dim] {
            continue;
        }
        let mut buckets = [(LightBounds::EMPTY, 0usize); BUCKETS];
        for item in items {
            let (b, count) = &mut buckets[bucket_of(item.centroid, centroids, dim)];
            *b = b.union(item.bounds);
            *count += 1;
        }
        // below[i]: buckets 0..=i; the rest is swept from the top.
        let mut below = [(LightBounds::EMPTY, 0usize); BUCKETS];
        let mut acc = (LightBounds::EMPTY, 0);
        for (i, &(b, count)) in buckets.iter().enumerate() {
            acc = (acc.0.union(b), acc.1 + count);
            below[i] = acc;
        }
        let mut above = (LightBounds::EMPTY, 0);
        for i in (0..BUCKETS - 1).rev() {
            above = (above.0.union(buckets[i + 1].0), above.1 + buckets[i + 1].1);
            if below[i].1 == 0 || above.1 == 0 {
                continue;
            }
            let cost = cost(&below[i].0, &all, dim) + cost(&above.0, &all, dim);
            if cost > 0.0 && best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, dim, i));
            }
        }
    }
    best.map(|(_, dim, bucket)| (dim, bucket))
}

/// The SAH cost of a child of bounds `b` in a node of box `node`: power
/// times the orientation measure `M_Omega` of its cones times its surface
/// area, with splits across a thin axis penalised by `K_r` (pbrt-v4
/// `BVHLightSampler::EvaluateCost`, Conty Estevez and Kulla 2018 eq. 3).
fn cost(b: &LightBounds, node: &Aabb, dim: usize) -> f32 {
    use std::f32::consts::PI;
    let theta_o = b.cos_theta_o.clamp(-1.0, 1.0).acos();
    let theta_e = b.cos_theta_e.clamp(-1.0, 1.0).acos();
    let theta_w = (theta_o + theta_e).min(PI);
    let sin_o = (1.0 - b.cos_theta_o * b.cos_theta_o).max(0.0).sqrt();
    let m_omega = 2.0 * PI * (1.0 - b.cos_theta_o)
        + PI / 2.0
            * (2.0 * theta_w * sin_o - (theta_o - 2.0 * theta_w).cos() - 2.0 * theta_o * sin_o
                + b.cos_theta_o);
    let d = node.diagonal();
    let k_r = d.max_element() / d[dim];
    b.phi * m_omega * k_r * b.bounds.surface_area()
}

#[cfg(test)]
mod tests {
    use super::*;
    use lumis_sampling::Pcg32;

    fn quad_at(center: Vec3, n: Vec3, half: f32, phi: f32, two_sided: bool) -> LightBounds {
        LightBounds::planar(
            Aabb::of_points([center - Vec3::splat(half), center + Vec3::splat(half)]),
            n,
            phi,
            two_sided,
        )
    }

    /// Lights spread over a box, of varied sizes, powers and facings; one
    /// dark, one infinite when `with_infinite`.
    fn scene(count: usize, with_infinite: bool, seed: u64) -> Vec<Option<LightBounds>> {
        let mut rng = Pcg32::new(seed, 3);
        let mut lights: Vec<_> = (0..count)
            .map(|i| {
                let mut c = || 8.0 * rng.next_f32() - 4.0;
                let center = Vec3::new(c(), c(), c());
                let n = Vec3::new(c(), c(), c()).normalize();
                let phi = 10f32.powf(3.0 * rng.next_f32());
                match i % 4 {
                    0 => Some(LightBounds::isotropic_point(center, phi)),
                    1 => Some(quad_at(center, n, 0.01, phi, true)),
                    _ => Some(quad_at(center, n, 0.3 * rng.next_f32(), phi, false)),
                }
            })
            .collect();
        lights.push(Some(quad_at(Vec3::ZERO, Vec3::Y, 1.0, 0.0, false)));
        if with_infinite {
            lights.push(None);
        }
        lights
    }

    fn contexts(seed: u64) -> Vec<LightSampleContext> {
        let mut rng = Pcg32::new(seed, 9);
        (0..64)
            .map(|i| {
                let scale = if i % 8 == 0 { 100.0 } else { 5.0 };
                let mut c = || scale * (2.0 * rng.next_f32() - 1.0);
                let mut ctx = LightSampleContext::at(Vec3::new(c(), c(), c()));
                if i % 2 == 0 {
                    ctx.ns = Vec3::new(c(), c(), c()).normalize_or(Vec3::Y);
                }
                ctx
            })
            .collect()
    }

    /// Follows every tree light's trail down from the root to its leaf.
    fn assert_trails_lead_to_leaves(s: &BvhLightSampler) {
        for (index, slot) in s.slots.iter().enumerate() {
            let Slot::Tree { mut trail } = *slot else {
                continue;
            };
            let mut node = 0;
            while !s.nodes[node].is_leaf {
                node = if trail & 1 == 0 {
                    node + 1
                } else {
                    s.nodes[node].child_or_light as usize
                };
                trail >>= 1;
            }
            assert_eq!(s.nodes[node].child_or_light as usize, index);
        }
    }

    #[test]
    fn every_leaf_is_reached_by_its_trail() {
        let lights = scene(300, true, 1);
        let s = BvhLightSampler::from_bounds(lights.iter().copied());
        assert_eq!(s.tree_lights(), 300);
        assert_eq!(s.nodes.len(), 2 * 300 - 1);
        assert_trails_lead_to_leaves(&s);
        assert_eq!(s.slots[300], Slot::Dark);
        assert_eq!(s.slots[301], Slot::Infinite);
    }

    /// From points near, far, on the surfaces and behind one-sided lights,
    /// the pmf is finite and sums to one less what dead ends lose; every
    /// draw reports the pmf that `pmf` gives its light.
    #[test]
    fn pmf_sums_to_one_and_matches_sample() {
        for with_infinite in [false, true] {
            let lights = scene(200, with_infinite, 2);
            let s = BvhLightSampler::from_bounds(lights.iter().copied());
            let mut on_lights: Vec<_> = lights
                .iter()
                .flatten()
                .take(20)
                .map(|b| LightSampleContext::at(b.bounds.center()))
                .collect();
            on_lights.extend(contexts(3));
            for ctx in &on_lights {
                let pmf: Vec<f32> = (0..lights.len() as u32).map(|i| s.pmf(ctx, i)).collect();
                assert!(pmf.iter().all(|p| p.is_finite() && (0.0..=1.0).contains(p)));
                let sum: f64 = pmf.iter().map(|&p| f64::from(p)).sum();
                // What `sample` returns nothing for: dead ends.
                let n = 4096;
                let mut none = 0;
                for k in 0..n {
                    let u = (k as f32 + 0.5) / n as f32;
                    match s.sample(ctx, u) {
                        Some(l) => {
                            assert!(l.pmf > 0.0);
                            let expected = pmf[l.index as usize];
                            assert!(
                                (l.pmf - expected).abs() <= 1e-6 * expected,
                                "{} vs {expected}",
                                l.pmf
                            );
                        }
                        None => none += 1,
                    }
                }
                let lost = none as f64 / n as f64;
                assert!(sum <= 1.0 + 1e-5, "{sum}");
                assert!((sum + lost - 1.0).abs() < 0.01, "sum {sum}, lost {lost}");
                assert_eq!(
                    s.pmf(ctx, lights.len() as u32 - 1 - with_infinite as u32),
                    0.0
                );
            }
        }
    }

    #[test]
    fn infinite_lights_take_everything_where_the_tree_is_dark() {
        // One light facing up, seen from below, and an environment.
        let lights = [Some(quad_at(Vec3::ZERO, Vec3::Y, 0.5, 1.0, false)), None];
        let s = BvhLightSampler::from_bounds(lights);
        let below = LightSampleContext::at(Vec3::new(0.0, -3.0, 0.0));
        assert_eq!(s.pmf(&below, 0), 0.0);
        assert_eq!(s.pmf(&below, 1), 1.0);
        assert_eq!(s.sample(&below, 0.99).map(|l| l.index), Some(1));
        let above = LightSampleContext::at(Vec3::new(0.0, 3.0, 0.0));
        assert_eq!(s.pmf(&above, 0), 0.5);
        assert_eq!(s.sample(&above, 0.7).map(|l| l.index), Some(0));
        assert!(BvhLightSampler::from_bounds([])
            .sample(&above, 0.5)
            .is_none());
    }

    /// Enough lights for the top of the tree to be built on two threads,
    /// its subtrees spliced together.
    #[test]
    fn parallel_builds_splice_their_subtrees() {
        let count = 3 * PARALLEL_MIN;
        let s = BvhLightSampler::from_bounds(scene(count, false, 4));
        assert_eq!(s.tree_lights(), count);
        assert_trails_lead_to_leaves(&s);
        let ctx = LightSampleContext::at(Vec3::new(0.5, 6.0, -1.0));
        let sum: f64 = (0..count as u32).map(|i| f64::from(s.pmf(&ctx, i))).sum();
        assert!(sum <= 1.0 + 1e-4 && sum > 0.9, "{sum}");
    }

    /// A million triangle lights (pbrt-scale scenes): the build and the pmf
    /// stay exact. Half a minute of CPU; `cargo test -p
    /// lumis-light-samplers -- --ignored --nocapture` prints the build time.
    #[test]
    #[ignore]
    fn a_million_lights() {
        let count = 1 << 20;
        let mut rng = Pcg32::new(7, 1);
        let lights: Vec<_> = (0..count)
            .map(|_| {
                let mut c = || 100.0 * rng.next_f32() - 50.0;
                let p0 = Vec3::new(c(), c(), c());
                let mut e = || 0.2 * rng.next_f32() - 0.1;
                let p = [
                    p0,
                    p0 + Vec3::new(e(), e(), e()),
                    p0 + Vec3::new(e(), e(), e()),
                ];
                let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or(Vec3::Y);
                Some(LightBounds::planar(
                    Aabb::of_points(p),
                    n,
                    1.0 + 9.0 * rng.next_f32(),
                    false,
                ))
            })
            .collect();
        let start = std::time::Instant::now();
        let s = BvhLightSampler::from_bounds(lights);
        eprintln!(
            "built the light BVH over {count} triangles in {:.2} s",
            start.elapsed().as_secs_f64()
        );
        assert_eq!(s.tree_lights(), count);
        assert_trails_lead_to_leaves(&s);
        for ctx in contexts(8).iter().take(4) {
            let sum: f64 = (0..count as u32).map(|i| f64::from(s.pmf(ctx, i))).sum();
            assert!(sum <= 1.0 + 1e-3 && sum > 0.5, "{sum}");
            for k in 0..1000 {
                if let Some(l) = s.sample(ctx, (k as f32 + 0.5) / 1000.0) {
                    let expected = s.pmf(ctx, l.index);
                    assert!((l.pmf - expected).abs() <= 1e-6 * expected);
                }
            }
        }
    }

    #[test]
    fn deep_degenerate_trees_stay_within_the_trail() {
        // Identical point lights: no SAH split separates them.
        let lights = vec![Some(LightBounds::isotropic_point(Vec3::ONE, 1.0)); 1000];
        let s = BvhLightSampler::from_bounds(lights);
        let ctx = LightSampleContext::at(Vec3::ZERO);
        let sum: f32 = (0..1000).map(|i| s.pmf(&ctx, i)).sum();
        assert!((sum - 1.0).abs() < 1e-4);
    }
}
