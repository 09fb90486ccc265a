//! The integer points of a box of the lattice, the walk every lattice sum of the method takes
//! (the kernel's moments on a lattice, the interface distance table, the spray density).

/// Calls `f` for every integer point k with lo ≤ k < hi, x fastest.
pub fn for_each_lattice_point<const D: usize>(
    lo: [i64; D],
    hi: [i64; D],
    mut f: impl FnMut([i64; D]),
) {
    if (0..D).any(|d| hi[d] <= lo[d]) {
        return;
    }
    let mut k = lo;
    loop {
        f(k);
        let mut d = 0;
        loop {
            k[d] += 1;
            if k[d] < hi[d] {
                break;
            }
            k[d] = lo[d];
            d += 1;
            if d == D {
                return;
            }
        }
    }
}
