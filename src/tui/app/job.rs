//! A background job of the editor (exploring, measuring accuracy): a thread
//! that reports into shared state and reads a cancel flag, polled by the
//! event loop and joined when it has said it is done.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;

/// A running job; clones share it.
pub struct Job<S> {
    shared: Arc<Mutex<S>>,
    cancel: Arc<AtomicBool>,
    thread: Arc<Mutex<Option<JoinHandle<()>>>>,
}

impl<S> Clone for Job<S> {
    fn clone(&self) -> Self {
        Job {
            shared: Arc::clone(&self.shared),
            cancel: Arc::clone(&self.cancel),
            thread: Arc::clone(&self.thread),
        }
    }
}

impl<S> std::fmt::Debug for Job<S> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Job")
    }
}

impl<S> PartialEq for Job<S> {
    fn eq(&self, other: &Job<S>) -> bool {
        Arc::ptr_eq(&self.shared, &other.shared)
    }
}

impl<S: Default + Send + 'static> Job<S> {
    /// Run `work` on a thread named `name`; it reports through the shared
    /// state and reads the cancel flag.
    pub fn spawn(
        name: &str,
        work: impl FnOnce(&Mutex<S>, &AtomicBool) + Send + 'static,
    ) -> std::io::Result<Job<S>> {
        let shared = Arc::new(Mutex::new(S::default()));
        let cancel = Arc::new(AtomicBool::new(false));
        let (s, c) = (Arc::clone(&shared), Arc::clone(&cancel));
        let handle = std::thread::Builder::new()
            .name(name.into())
            .spawn(move || work(&s, &c))?;
        Ok(Job {
            shared,
            cancel,
            thread: Arc::new(Mutex::new(Some(handle))),
        })
    }
}

impl<S> Job<S> {
    /// Read or take from the shared state; `None` if the thread panicked
    /// while holding it.
    pub fn with<T>(&self, f: impl FnOnce(&mut S) -> T) -> Option<T> {
        self.shared.lock().ok().map(|mut s| f(&mut s))
    }

    /// Ask the thread to stop at its next check.
    pub fn cancel(&self) {
        self.cancel.store(true, Ordering::Relaxed);
    }

    /// Wait for the thread to end (at once if it has been joined).
    pub fn join(&self) {
        let handle = self.thread.lock().ok().and_then(|mut t| t.take());
        if let Some(h) = handle {
            let _ = h.join();
        }
    }
}
