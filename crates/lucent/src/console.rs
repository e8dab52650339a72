//! Printing that cannot end a run. `println!` and `eprintln!` panic when their stream is
//! closed (`lucent check … | head -1`, `2>&1 | true`, a terminal that went away); these
//! lose the text instead. What a command prints never decides its outcome: its exit code
//! and the files it writes do, and a render whose log nobody reads still writes its image.

/// `println!` whose failure (a closed standard output) loses the line.
macro_rules! outln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($arg)*);
    }};
}

/// `print!` whose failure loses the text.
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = write!(std::io::stdout(), $($arg)*);
    }};
}

/// `eprintln!` whose failure (a closed standard error) loses the line.
macro_rules! errln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

/// `eprint!` whose failure loses the text.
macro_rules! err {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = write!(std::io::stderr(), $($arg)*);
    }};
}
