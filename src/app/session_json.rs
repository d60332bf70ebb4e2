//! Session files as people read them: pretty JSON with each point on one line.

/// Pretty JSON with each array of plain numbers (a point, a triangle) on one
/// line: a 40-vertex pose is 40 lines, not 200.
pub(super) fn one_point_per_line(pretty: &str) -> String {
    let lines: Vec<&str> = pretty.lines().collect();
    let mut out = String::with_capacity(pretty.len());
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i];
        if line.trim_end().ends_with('[') {
            // The numbers up to the closing bracket, if that is all there is.
            let numbers: Vec<&str> = lines[i + 1..]
                .iter()
                .map(|l| l.trim().trim_end_matches(','))
                .take_while(|l| l.parse::<f64>().is_ok())
                .collect();
            if let Some(close) = lines.get(i + 1 + numbers.len()) {
                let close = close.trim();
                if !numbers.is_empty() && (close == "]" || close == "],") {
                    out.push_str(line.trim_end());
                    out.push_str(&numbers.join(", "));
                    out.push_str(close);
                    out.push('\n');
                    i += numbers.len() + 2;
                    continue;
                }
            }
        }
        out.push_str(line);
        out.push('\n');
        i += 1;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_take_one_line_each_and_read_back_the_same() {
        let value = serde_json::json!({
            "pose": [[0.1, -2.0, 3e-9], [1.0, 2.0, 3.0]],
            "names": ["a", "b"],
            "empty": [],
            "nested": {"triangles": [[0, 1, 2]]}
        });
        let pretty = serde_json::to_string_pretty(&value).unwrap();
        let compact = one_point_per_line(&pretty);
        assert!(compact.contains("    [0.1, -2.0, 3e-9],\n"), "{compact}");
        assert!(compact.contains("[0, 1, 2]"), "{compact}");
        assert!(
            compact.contains("\"a\",\n"),
            "strings stay one per line: {compact}"
        );
        assert_eq!(
            serde_json::from_str::<serde_json::Value>(&compact).unwrap(),
            value
        );
        assert!(compact.lines().count() < pretty.lines().count());
    }
}
