//! Results of work done in parallel, one per experiment (or job), with the first failure taken
//! in their order.
//!
//! rayon's `collect::<Result<_, _>>()` stops at the failure that *finishes* first, so the same
//! input could name a different experiment on every run (`compare` once named v0p53_p2 for a
//! take-up missing in all nine). Every user-facing error of a parallel loop goes through
//! [`CollectInOrder::collect_in_order`] instead.

use rayon::iter::ParallelIterator;

/// `collect` into a `Vec` that returns the first error in the iterator's order.
pub(crate) trait CollectInOrder<T, E> {
    /// Every result, in order, or the first error in that order (all items are computed: a
    /// loop whose failures should stop the others early, such as a fit's trial step, keeps
    /// rayon's own `collect`).
    fn collect_in_order(self) -> Result<Vec<T>, E>;
}

impl<I, T, E> CollectInOrder<T, E> for I
where
    I: ParallelIterator<Item = Result<T, E>>,
    T: Send,
    E: Send,
{
    fn collect_in_order(self) -> Result<Vec<T>, E> {
        // rayon's collect into a Vec keeps the order of every parallel iterator
        self.collect::<Vec<_>>().into_iter().collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    #[test]
    fn the_first_error_in_order_whatever_finishes_first() {
        // the later failures are cheap, the first one slow: it finishes last
        let r: Result<Vec<usize>, usize> = (0..64usize)
            .into_par_iter()
            .map(|k| match k {
                5 => {
                    std::thread::sleep(std::time::Duration::from_millis(30));
                    Err(5)
                }
                k if k > 5 => Err(k),
                k => Ok(k),
            })
            .collect_in_order();
        assert_eq!(r, Err(5));
        let ok: Result<Vec<usize>, usize> = (0..64usize).into_par_iter().map(Ok).collect_in_order();
        assert_eq!(ok, Ok((0..64).collect()));
        // the order of a filtered iterator is kept too
        let odd: Result<Vec<usize>, usize> = (0..64usize)
            .into_par_iter()
            .filter_map(|k| (k % 2 == 1).then_some(Ok(k)))
            .collect_in_order();
        assert_eq!(odd, Ok((0..32).map(|k| 2 * k + 1).collect()));
    }
}
