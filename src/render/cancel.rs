//! Cooperative cancellation of renders. A caller that wants to stop a
//! render early (the Python package on Ctrl-C) runs it in its own rayon
//! pool whose workers carry a flag, set with [`set_thread_flag`] from the
//! pool's start handler; the render polls the flag between blocks and
//! chunks of samples and returns [`Cancelled`] once it is set. Threads
//! without a flag (the CLI's pools) are never cancelled.

use std::cell::RefCell;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

thread_local! {
    static FLAG: RefCell<Option<Arc<AtomicBool>>> = const { RefCell::new(None) };
}

/// The error a cancelled render returns.
#[derive(Debug, thiserror::Error)]
#[error("render cancelled")]
pub struct Cancelled;

/// Makes the calling thread watch `flag` (call it from a rayon pool's
/// `start_handler`).
pub fn set_thread_flag(flag: Arc<AtomicBool>) {
    FLAG.with(|f| *f.borrow_mut() = Some(flag));
}

/// Whether the calling thread's flag is set.
pub fn cancelled() -> bool {
    FLAG.with(|f| {
        f.borrow()
            .as_ref()
            .is_some_and(|a| a.load(Ordering::Relaxed))
    })
}

/// `Err(Cancelled)` once the calling thread's flag is set.
pub fn check() -> Result<(), Cancelled> {
    if cancelled() { Err(Cancelled) } else { Ok(()) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_flagged_threads_see_the_flag() {
        assert!(check().is_ok());
        let flag = Arc::new(AtomicBool::new(false));
        let f2 = flag.clone();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .start_handler(move |_| set_thread_flag(f2.clone()))
            .build()
            .unwrap();
        assert!(pool.install(|| check().is_ok()));
        flag.store(true, Ordering::Relaxed);
        assert!(pool.install(|| check().is_err()));
        assert!(check().is_ok());
    }
}
