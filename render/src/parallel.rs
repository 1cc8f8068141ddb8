//! Making a pass's pipelines on every core: a driver compiles a pipeline's shaders when it is
//! made (lavapipe's for a mesh's glass take seconds each), and Vulkan lets any thread make
//! pipelines without a pipeline cache.

use std::sync::atomic::{AtomicUsize, Ordering};

use crate::error::Result;

/// `make` of each of `items` (a pass's pipelines), in their order, made on as many threads as
/// the machine has cores: a driver compiles a pipeline's shaders when it is made, which for a
/// mesh's glass on a CPU device takes seconds each. The first error in the items' order, with
/// whatever was made dropped (destroyed).
pub(crate) fn in_parallel<T: Sync, R: Send>(
    items: &[T],
    make: impl Fn(&T) -> Result<R> + Sync,
) -> Result<Vec<R>> {
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(items.len());
    if threads <= 1 {
        return items.iter().map(make).collect();
    }
    let next = AtomicUsize::new(0);
    // Each thread takes the next item not yet taken, and keeps its index.
    let work = || {
        let mut made = Vec::new();
        loop {
            let index = next.fetch_add(1, Ordering::Relaxed);
            let Some(item) = items.get(index) else {
                return made;
            };
            made.push((index, make(item)));
        }
    };
    let mut made: Vec<_> = std::thread::scope(|scope| {
        let workers: Vec<_> = (0..threads).map(|_| scope.spawn(work)).collect();
        workers
            .into_iter()
            .flat_map(|w| w.join().unwrap_or_else(|p| std::panic::resume_unwind(p)))
            .collect()
    });
    made.sort_by_key(|&(index, _)| index);
    made.into_iter().map(|(_, r)| r).collect()
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::in_parallel;
    use crate::error::RenderError;

    #[test]
    fn pipelines_made_in_parallel_come_back_in_their_order() {
        let items: Vec<u32> = (0..100).collect();
        let made = in_parallel(&items, |&i| Ok(i * 3)).unwrap();
        assert_eq!(made, items.iter().map(|i| i * 3).collect::<Vec<_>>());
        assert!(in_parallel(&[] as &[u32], |&i| Ok(i)).unwrap().is_empty());
    }

    #[test]
    fn the_first_failure_in_order_is_returned_and_everything_made_dropped() {
        let alive = Arc::new(());
        let items: Vec<u32> = (0..64).collect();
        let result = in_parallel(&items, |&i| match i {
            9 | 40 => Err(RenderError::InvalidInput(format!("item {i}"))),
            _ => Ok(Arc::clone(&alive)),
        });
        match result {
            Err(RenderError::InvalidInput(what)) => assert_eq!(what, "item 9"),
            other => panic!("not the first failure: {:?}", other.map(|v| v.len())),
        }
        assert_eq!(Arc::strong_count(&alive), 1, "every item made was dropped");
    }
}
