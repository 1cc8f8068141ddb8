//! OpenXR's two-call idiom for arrays the layer answers itself: a call with capacity 0 asks
//! for the count; a call with a smaller, non-zero capacity gets the count and
//! `XR_ERROR_SIZE_INSUFFICIENT`; a large enough one gets the elements.

use openxr::sys;

/// Answers a two-call-idiom query for `items`: writes the count to `count_out` and, when
/// `capacity` is large enough, the elements to `out`.
///
/// `out` is `None` when the caller passed a null array; that is allowed only with capacity 0.
pub fn answer<T: Copy>(
    items: &[T],
    capacity: u32,
    count_out: Option<&mut u32>,
    out: Option<&mut [T]>,
) -> sys::Result {
    answer_with(items.len(), capacity, count_out, out, |slot, i| {
        *slot = items[i]
    })
}

/// The two-call idiom for `len` elements that `fill(slot, index)` writes in place (so output
/// structures keep the `type` and `next` the caller set).
pub fn answer_with<T>(
    len: usize,
    capacity: u32,
    count_out: Option<&mut u32>,
    out: Option<&mut [T]>,
    mut fill: impl FnMut(&mut T, usize),
) -> sys::Result {
    let Some(count_out) = count_out else {
        return sys::Result::ERROR_VALIDATION_FAILURE;
    };
    let Ok(len32) = u32::try_from(len) else {
        return sys::Result::ERROR_RUNTIME_FAILURE;
    };
    *count_out = len32;
    if capacity == 0 {
        return sys::Result::SUCCESS;
    }
    if capacity < len32 {
        return sys::Result::ERROR_SIZE_INSUFFICIENT;
    }
    let Some(out) = out else {
        return sys::Result::ERROR_VALIDATION_FAILURE;
    };
    for (i, slot) in out.iter_mut().take(len).enumerate() {
        fill(slot, i);
    }
    sys::Result::SUCCESS
}

/// The output slice of a two-call-idiom call: `None` for a null array or capacity 0.
///
/// # Safety
/// `out` must be null or valid for reads and writes of `capacity` elements for `'a`.
pub unsafe fn out_slice<'a, T>(capacity: u32, out: *mut T) -> Option<&'a mut [T]> {
    if out.is_null() || capacity == 0 {
        None
    } else {
        // SAFETY: the caller guarantees `out` holds `capacity` elements for `'a`.
        Some(unsafe { std::slice::from_raw_parts_mut(out, capacity as usize) })
    }
}

/// [`answer`] on raw pointers.
///
/// # Safety
/// `count_out` must be null or valid for a write; `out` must be null or valid for writes of
/// `capacity` elements.
pub unsafe fn answer_raw<T: Copy>(
    items: &[T],
    capacity: u32,
    count_out: *mut u32,
    out: *mut T,
) -> sys::Result {
    // SAFETY: the caller guarantees `count_out` is null or writable.
    let count = unsafe { count_out.as_mut() };
    // SAFETY: the caller guarantees `out` is null or holds `capacity` writable elements.
    let slice = unsafe { out_slice(capacity, out) };
    answer(items, capacity, count, slice)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn capacity_zero_asks_for_the_count() {
        let mut n = 99;
        assert_eq!(
            answer(&[1, 2, 3], 0, Some(&mut n), None),
            sys::Result::SUCCESS
        );
        assert_eq!(n, 3);
    }

    #[test]
    fn too_small_a_capacity_gets_the_count_and_an_error() {
        let mut n = 0;
        let mut out = [0; 2];
        assert_eq!(
            answer(&[1, 2, 3], 2, Some(&mut n), Some(&mut out)),
            sys::Result::ERROR_SIZE_INSUFFICIENT
        );
        assert_eq!((n, out), (3, [0, 0]), "nothing is written");
    }

    #[test]
    fn enough_capacity_gets_the_elements() {
        let mut n = 0;
        let mut out = [0; 5];
        assert_eq!(
            answer(&[1, 2, 3], 5, Some(&mut n), Some(&mut out)),
            sys::Result::SUCCESS
        );
        assert_eq!((n, out), (3, [1, 2, 3, 0, 0]));
    }

    #[test]
    fn missing_pointers_are_validation_failures() {
        assert_eq!(
            answer(&[1], 0, None, None),
            sys::Result::ERROR_VALIDATION_FAILURE
        );
        let mut n = 0;
        assert_eq!(
            answer(&[1], 4, Some(&mut n), None),
            sys::Result::ERROR_VALIDATION_FAILURE
        );
    }

    #[test]
    fn an_empty_list_is_answered_with_zero() {
        let mut n = 7;
        let mut out = [5; 1];
        assert_eq!(
            answer::<i32>(&[], 1, Some(&mut n), Some(&mut out)),
            sys::Result::SUCCESS
        );
        assert_eq!((n, out), (0, [5]));
        // SAFETY: `n` is writable and `out` holds one element.
        let r = unsafe { answer_raw::<i32>(&[2], 1, &mut n, out.as_mut_ptr()) };
        assert_eq!((r, n, out), (sys::Result::SUCCESS, 1, [2]));
    }
}
