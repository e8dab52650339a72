//! What a run takes from the machine, taken with care: files in — only regular files of
//! a bounded size ([`input`]); files out — never replacing anything but a regular file,
//! and never one of the run's inputs ([`output`]); and memory — a budget checked before
//! anything large is made ([`budget`]).

pub mod budget;
pub mod input;
pub mod output;

pub use budget::Budget;
pub use input::{open_input, read_input, Inputs};
pub use output::{write_together, OutputTarget};

/// What loading a scene keeps track of: the files it has read and the memory it may
/// still take.
#[derive(Clone, Debug)]
pub struct Resources {
    pub inputs: Inputs,
    pub budget: Budget,
}

impl Resources {
    pub fn new(memory_limit: u64) -> Resources {
        Resources {
            inputs: Inputs::default(),
            budget: Budget::new(memory_limit),
        }
    }
}

/// The reason an I/O operation failed, in a few words ("no such file").
pub fn io_reason(e: &std::io::Error) -> String {
    match e.kind() {
        std::io::ErrorKind::NotFound => "no such file".into(),
        std::io::ErrorKind::PermissionDenied => "permission denied".into(),
        _ => {
            let s = e.to_string();
            s.split(" (os error").next().unwrap_or(&s).to_lowercase()
        }
    }
}
