//! Islands: the beads that constraints and springs join, grouped so that
//! each group is solved on its own.

/// Groups `beads` beads into islands, given the beads each link joins (a
/// constraint's beads, a spring's two). Each island lists its beads in
/// increasing order; islands come in the order of their smallest bead. A
/// bead no link names is an island of its own.
pub fn islands<'a>(beads: usize, links: impl IntoIterator<Item = &'a [usize]>) -> Vec<Vec<usize>> {
    let mut parent: Vec<usize> = (0..beads).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for link in links {
        let mut named = link.iter().copied().filter(|&b| b < beads);
        let Some(first) = named.next() else { continue };
        for other in named {
            let (a, b) = (root(&mut parent, first), root(&mut parent, other));
            if a != b {
                parent[a.max(b)] = a.min(b);
            }
        }
    }
    let mut index = vec![usize::MAX; beads];
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for bead in 0..beads {
        let r = root(&mut parent, bead);
        if index[r] == usize::MAX {
            index[r] = groups.len();
            groups.push(Vec::new());
        }
        groups[index[r]].push(bead);
    }
    groups
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn links_join_beads_into_islands() {
        let links: [&[usize]; 4] = [&[0, 3], &[3, 5], &[2], &[4, 1]];
        assert_eq!(
            islands(7, links),
            vec![vec![0, 3, 5], vec![1, 4], vec![2], vec![6]]
        );
    }
}
