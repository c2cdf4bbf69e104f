//! Reading back the waves a mismatch writes: enough to check that a VCD file records the
//! clocks of its window, not only its header.

/// How many times the top-level `clock` changes value in a VCD text (0 when it has no such
/// signal).
pub fn clock_changes(vcd: &str) -> usize {
    let Some((head, body)) = vcd.split_once("$enddefinitions") else {
        return 0;
    };
    // `$var wire 1 <id> clock $end`, the first one (the top's port).
    let id = head.lines().find_map(|l| {
        let t: Vec<&str> = l.split_whitespace().collect();
        (t.len() >= 6 && t[0] == "$var" && t[4] == "clock").then(|| t[3].to_string())
    });
    let Some(id) = id else { return 0 };
    body.lines()
        .filter(|l| {
            let l = l.trim();
            (l.starts_with('0') || l.starts_with('1')) && l[1..] == id
        })
        .count()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_the_clock_and_nothing_else() {
        let vcd = "$scope module TOP $end\n $var wire  1 ! clock $end\n $var wire  1 \" d $end\n\
                   $upscope $end\n$enddefinitions $end\n#0\n0!\n1\"\n#1\n1!\n#2\n0!\n0\"\n";
        assert_eq!(clock_changes(vcd), 3);
        assert_eq!(clock_changes("$var wire 1 ! clock $end\n"), 0);
    }
}
