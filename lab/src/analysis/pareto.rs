//! The Pareto front of (cost, error) points: the configurations no other configuration beats on
//! both at once.

/// Indices of the points on the Pareto front of `points` = (cost, error), both minimised, sorted
/// by cost. A point is on the front when no other point is at most as costly and at most as wrong
/// with one of the two strictly smaller; of exact duplicates the first is kept. Points with a NaN
/// coordinate are never on the front.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..points.len())
        .filter(|&i| !points[i].0.is_nan() && !points[i].1.is_nan())
        .collect();
    // By cost, then by error, then by index: a sweep keeps the running minimum error.
    order.sort_by(|&a, &b| {
        points[a]
            .0
            .total_cmp(&points[b].0)
            .then(points[a].1.total_cmp(&points[b].1))
            .then(a.cmp(&b))
    });
    let mut front = Vec::new();
    let mut best = f64::INFINITY;
    for i in order {
        if points[i].1 < best {
            best = points[i].1;
            front.push(i);
        }
    }
    front
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn front_of_a_known_point_set() {
        // 0 and 2 dominate 1 and 3; 4 is the cheapest; 5 duplicates 2; 6 is NaN.
        let p = [
            (2.0, 0.5),
            (3.0, 0.6),
            (5.0, 0.1),
            (5.0, 0.2),
            (1.0, 0.9),
            (5.0, 0.1),
            (0.5, f64::NAN),
            (9.0, 0.1),
            (8.0, 0.0),
        ];
        assert_eq!(pareto_front(&p), vec![4, 0, 2, 8]);
        assert!(pareto_front(&[]).is_empty());
        // Brute-force definition on a pseudo-random set.
        let mut s = 12345u64;
        let mut rnd = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 40) as f64 / (1u64 << 24) as f64
        };
        let q: Vec<(f64, f64)> = (0..300).map(|_| (rnd(), rnd())).collect();
        let f = pareto_front(&q);
        for (i, a) in q.iter().enumerate() {
            let dominated = q
                .iter()
                .any(|b| b.0 <= a.0 && b.1 <= a.1 && (b.0 < a.0 || b.1 < a.1));
            assert_eq!(f.contains(&i), !dominated, "point {i} {a:?}");
        }
    }
}
