//! The node graph of a glTF file must be a forest; [`check_hierarchy`]
//! refuses what is not, before any transform is applied.

/// glTF's nodes form a forest (disjoint trees): refuse a child index out of
/// range, a child listed twice, a node with two parents and a cycle, naming
/// the nodes. A transform is applied once per node on the way to a root, so
/// a cycle would apply one twice.
pub(super) fn check_hierarchy(nodes: &[gltf::json::Node]) -> Result<(), String> {
    let count = nodes.len();
    let mut parents: Vec<Option<usize>> = vec![None; count];
    for (n, node) in nodes.iter().enumerate() {
        for child in node.children.iter().flatten() {
            let c = child.value();
            if c >= count {
                return Err(format!(
                    "node {n} lists child {c}, but the file has {count} nodes"
                ));
            }
            if c == n {
                return Err(format!("node {n} is a child of itself"));
            }
            match parents[c] {
                Some(p) if p == n => return Err(format!("node {n} lists child {c} twice")),
                Some(p) => return Err(format!("node {c} has two parents: nodes {p} and {n}")),
                None => parents[c] = Some(n),
            }
        }
    }
    // With one parent at most each, a walk from any node to its parents ends
    // at a root or goes round a cycle. Walks end where earlier ones went.
    const NEW: u8 = 0;
    const WALKING: u8 = 1;
    const DONE: u8 = 2;
    let mut state = vec![NEW; count];
    for start in 0..count {
        let mut at = start;
        while state[at] == NEW {
            state[at] = WALKING;
            match parents[at] {
                Some(parent) => at = parent,
                None => break,
            }
        }
        if state[at] == WALKING && parents[at].is_some() {
            return Err(cycle(&parents, at));
        }
        let mut at = start;
        while state[at] == WALKING {
            state[at] = DONE;
            match parents[at] {
                Some(parent) => at = parent,
                None => break,
            }
        }
    }
    Ok(())
}

/// The message for the cycle through node `on`, from its lowest node, each
/// node followed by the child it lists: "nodes 1, 2 and 3 form a cycle: node
/// 1 lists child 2, node 2 lists child 3, node 3 lists child 1". A long
/// cycle is cut short.
fn cycle(parents: &[Option<usize>], on: usize) -> String {
    const SHOWN: usize = 6;
    let up = |node: usize| parents[node].unwrap_or(node);
    let mut lowest = on;
    let mut at = up(on);
    while at != on {
        lowest = lowest.min(at);
        at = up(at);
    }
    // Up the cycle from its lowest node, then down: each node's child.
    let mut upwards = vec![lowest];
    let mut at = up(lowest);
    while at != lowest {
        upwards.push(at);
        at = up(at);
    }
    let mut order = vec![lowest];
    order.extend(upwards[1..].iter().rev());
    let length = order.len();
    let names: Vec<String> = order.iter().take(SHOWN).map(|n| n.to_string()).collect();
    let nodes = match names.split_last() {
        _ if length > SHOWN => format!("{} and {} more", names.join(", "), length - SHOWN),
        Some((last, others)) if !others.is_empty() => format!("{} and {last}", others.join(", ")),
        _ => names.join(""),
    };
    let links: Vec<String> = (0..length.min(SHOWN))
        .map(|k| format!("node {} lists child {}", order[k], order[(k + 1) % length]))
        .collect();
    let rest = if length > SHOWN { ", …" } else { "" };
    format!("nodes {nodes} form a cycle: {}{rest}", links.join(", "))
}
