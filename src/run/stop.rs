//! The flag that stops a run between two steps.

use std::sync::atomic::AtomicUsize;
use std::sync::Arc;

/// Set to a signal number (by a signal handler, or by any thread) to stop a run after its
/// current step: it then writes a checkpoint and returns `RunError::Interrupted`.
pub type StopSignal = Arc<AtomicUsize>;
