//! The commands around a run: `isph plan`, `isph bench`, `isph study`, `isph surface`, `isph measure` (the
//! validation measures), and the child processes that report their peak memory.

pub mod bench;
pub mod child;
pub mod plan;
pub mod study;
pub mod surface;
pub mod validation;
