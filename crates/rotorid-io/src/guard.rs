//! Third-party parsers of large formats (the `parquet` crate, `hdf5-pure`) run under
//! [`quietly`]: a panic in them on a hostile file becomes `None`, which the reader turns
//! into an error naming the file, and its message is not printed (a user sees the error,
//! not "thread 'main' panicked at ...").
//!
//! The message is kept off stderr by a panic hook installed once, on first use, that wraps
//! the hook in place then: on a thread inside [`quietly`] it prints nothing, anywhere else
//! it calls the previous hook, so panics elsewhere in the program are reported as before.
//! A hook the program installs later replaces it (the panic is still caught, only its
//! message then shows).

use std::cell::Cell;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::Once;

thread_local! {
    /// Depth of [`quietly`] calls on this thread.
    static QUIET: Cell<u32> = const { Cell::new(0) };
}

static HOOK: Once = Once::new();

/// `run()`, or `None` when it panicked (the panic is caught and its message not printed).
pub(crate) fn quietly<T>(run: impl FnOnce() -> T) -> Option<T> {
    HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if QUIET.with(Cell::get) == 0 {
                previous(info);
            }
        }));
    });
    QUIET.with(|q| q.set(q.get() + 1));
    let r = catch_unwind(AssertUnwindSafe(run));
    QUIET.with(|q| q.set(q.get() - 1));
    r.ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_inside_is_caught_and_the_depth_restored() {
        assert_eq!(quietly(|| 7), Some(7));
        let caught: Option<()> = quietly(|| panic!("a hostile file"));
        assert_eq!(caught, None);
        assert_eq!(quietly(|| quietly(|| 1)), Some(Some(1)));
        assert_eq!(QUIET.with(Cell::get), 0);
    }
}
