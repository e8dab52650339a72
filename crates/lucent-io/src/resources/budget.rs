//! The memory budget: what a run may take for what it builds — scene descriptions,
//! textures, meshes, tessellated surfaces and their acceleration structures — checked
//! *before* each is made from an estimate of its size, so that a scene that would need
//! more than the machine has is refused with a message at the command that asks for it
//! instead of ending in the kernel's out-of-memory killer or an abort.
//!
//! The default budget is three quarters of the machine's memory (`MemTotal`, or a smaller
//! cgroup limit), 4 GB where neither can be read; `--memory-limit` sets another.

use super::input::bytes;

/// Memory a triangle of a mesh costs once built: its share of the vertex arrays
/// (positions, normals, texture coordinates: up to 32 bytes a vertex, about half a
/// vertex a triangle in a closed mesh, a whole one in an open grid), its indices and
/// material (16 bytes), its share of the BVH (about 55 bytes) and of the build's
/// temporary arrays (about 40 bytes).
pub const BYTES_PER_TRIANGLE: u64 = 144;

#[derive(Clone, Debug)]
pub struct Budget {
    limit: u64,
    used: u64,
}

impl Budget {
    pub fn new(limit: u64) -> Budget {
        Budget { limit, used: 0 }
    }

    /// Three quarters of the machine's memory (see the module's documentation).
    pub fn machine_default() -> u64 {
        machine_memory().map_or(4_000_000_000, |m| m / 4 * 3)
    }

    pub fn limit(&self) -> u64 {
        self.limit
    }

    pub fn used(&self) -> u64 {
        self.used
    }

    pub fn remaining(&self) -> u64 {
        self.limit.saturating_sub(self.used)
    }

    /// Takes `bytes` for `what`, or says why it cannot.
    pub fn take(&mut self, n: u64, what: &str) -> Result<(), String> {
        if n > self.remaining() {
            return Err(format!(
                "{what} needs about {}, more than the {} left of the memory budget of {} (--memory-limit sets it)",
                bytes(n),
                bytes(self.remaining()),
                bytes(self.limit)
            ));
        }
        self.used += n;
        Ok(())
    }

    /// Gives back what a temporary took.
    pub fn give_back(&mut self, n: u64) {
        self.used = self.used.saturating_sub(n);
    }
}

/// The machine's memory in bytes: `MemTotal`, or the cgroup's limit if smaller.
fn machine_memory() -> Option<u64> {
    let total = std::fs::read_to_string("/proc/meminfo").ok().and_then(|s| {
        let line = s.lines().find(|l| l.starts_with("MemTotal:"))?;
        let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
        Some(kb * 1024)
    });
    let cgroup = std::fs::read_to_string("/sys/fs/cgroup/memory.max")
        .ok()
        .and_then(|s| s.trim().parse::<u64>().ok());
    match (total, cgroup) {
        (Some(t), Some(c)) => Some(t.min(c)),
        (t, c) => t.or(c),
    }
}

/// A memory size as people write it: `4G`, `512M`, `1.5GiB`, `800000000`.
pub fn parse_size(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let split = t.find(|c: char| !(c.is_ascii_digit() || c == '.')).unwrap_or(t.len());
    let (number, unit) = t.split_at(split);
    let x: f64 = number
        .parse()
        .map_err(|_| format!("'{s}' is not a size (a number with K, M, G or T)"))?;
    let scale = match unit.trim().to_ascii_lowercase().as_str() {
        "" | "b" => 1.0,
        "k" | "kb" => 1e3,
        "kib" => 1024.0,
        "m" | "mb" => 1e6,
        "mib" => 1024.0 * 1024.0,
        "g" | "gb" => 1e9,
        "gib" => 1024.0 * 1024.0 * 1024.0,
        "t" | "tb" => 1e12,
        "tib" => 1024.0f64.powi(4),
        _ => return Err(format!("'{s}': unknown unit '{unit}' (K, M, G or T)")),
    };
    let n = x * scale;
    if !(n.is_finite() && n >= 1.0 && n < 1e19) {
        return Err(format!("'{s}' is not a usable size"));
    }
    Ok(n as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_budget_refuses_what_it_cannot_hold() {
        let mut b = Budget::new(1000);
        b.take(600, "a texture").unwrap();
        let e = b.take(600, "a mesh").unwrap_err();
        assert!(
            e.starts_with("a mesh needs about 600 bytes, more than the 400 bytes left"),
            "{e}"
        );
        b.give_back(600);
        assert_eq!(b.remaining(), 1000);
        assert!(Budget::machine_default() > 100_000_000);
    }

    #[test]
    fn sizes_are_read_as_people_write_them() {
        assert_eq!(parse_size("4G").unwrap(), 4_000_000_000);
        assert_eq!(parse_size("512MiB").unwrap(), 512 << 20);
        assert_eq!(parse_size("1.5 GB").unwrap(), 1_500_000_000);
        assert_eq!(parse_size("800000000").unwrap(), 800_000_000);
        assert!(parse_size("lots").is_err() && parse_size("4X").is_err() && parse_size("0").is_err());
        assert!(parse_size("nan").is_err() && parse_size("-1G").is_err());
    }
}
