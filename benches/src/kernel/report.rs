//! The trade report (`benches/tradeoff.md`) as data: the one place measured per-test figures
//! live. The report binary writes it; the chart is drawn from it; the README's table is a copy of
//! it; rustdoc and README prose quote single cells of it as
//! `` <value> (report: `<row>`, <column>) ``, and `tests/figures.rs` fails when a quote drifts.

use std::path::PathBuf;

/// The report's tables: the main one (every kernel and peer: speed, accuracy, cracks) and the
/// ones after it, as column names and rows of cells, as written.
#[derive(Clone, Debug, PartialEq)]
pub struct Report {
    /// The text above the main table (machine, build, workload).
    pub preamble: String,
    /// The main table's column names.
    pub columns: Vec<String>,
    /// The main table's rows of cells, the first cell being the kernel's name.
    pub rows: Vec<Vec<String>>,
    /// The later tables (column names, rows), in order; quotes may name their cells too.
    pub more: Vec<(Vec<String>, Vec<Vec<String>>)>,
}

/// Where the report lives.
pub fn path() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/tradeoff.md"))
}

fn cells(line: &str) -> Vec<String> {
    let l = line.trim().trim_start_matches('|').trim_end_matches('|');
    l.split('|').map(|c| c.trim().to_string()).collect()
}

impl Report {
    /// Parses the report's markdown: the preamble, the main table, then any further tables.
    pub fn parse(md: &str) -> Result<Self, String> {
        let lines: Vec<&str> = md.lines().collect();
        let mut tables = vec![];
        let mut i = 0;
        let mut preamble = None;
        while i < lines.len() {
            if !lines[i].starts_with('|') {
                i += 1;
                continue;
            }
            preamble.get_or_insert_with(|| lines[..i].join("\n"));
            let columns = cells(lines[i]);
            if !lines.get(i + 1).is_some_and(|l| l.starts_with("|---")) {
                return Err("table header has no separator line".into());
            }
            let mut rows = vec![];
            i += 2;
            while i < lines.len() && lines[i].starts_with('|') {
                let row = cells(lines[i]);
                if row.len() != columns.len() {
                    return Err(format!(
                        "row has {} cells, header {}: {}",
                        row.len(),
                        columns.len(),
                        lines[i]
                    ));
                }
                rows.push(row);
                i += 1;
            }
            if rows.is_empty() {
                return Err("table has no rows".into());
            }
            tables.push((columns, rows));
        }
        if tables.is_empty() {
            return Err("no table in the report".into());
        }
        let (columns, rows) = tables.remove(0);
        Ok(Self {
            preamble: preamble.unwrap_or_default(),
            columns,
            rows,
            more: tables,
        })
    }

    /// Reads and parses `benches/tradeoff.md`.
    pub fn load() -> Result<Self, String> {
        let p = path();
        let md = std::fs::read_to_string(&p).map_err(|e| format!("{}: {e}", p.display()))?;
        Self::parse(&md)
    }

    /// The cell of `row` (a row's first cell, exactly) in `column` (a column name, exactly): in
    /// the main table, else in the first later table that has both.
    pub fn cell(&self, row: &str, column: &str) -> Option<&str> {
        core::iter::once((&self.columns, &self.rows))
            .chain(self.more.iter().map(|(c, r)| (c, r)))
            .find_map(|(columns, rows)| {
                let c = columns.iter().position(|x| x == column)?;
                let r = rows.iter().find(|r| r[0] == row)?;
                Some(r[c].as_str())
            })
    }

    /// The leading number of a cell (`"2.39 est."` → 2.39, `"1.540 %"` → 1.54).
    pub fn number(&self, row: &str, column: &str) -> Option<f64> {
        self.cell(row, column)?
            .split_whitespace()
            .next()?
            .parse()
            .ok()
    }

    /// The build the figures were measured with (from the preamble's `build: …;`).
    pub fn build(&self) -> &str {
        self.preamble
            .split("build: ")
            .nth(1)
            .and_then(|s| s.split(';').next())
            .unwrap_or("unknown build")
    }
}

/// The text of `src` with comment markers (`//!`, `///`, `//`) removed from the start of each line,
/// so that a quote broken across rustdoc lines reads as one.
pub fn prose(src: &str) -> String {
    src.lines()
        .map(|l| {
            let t = l.trim_start();
            t.strip_prefix("//!")
                .or_else(|| t.strip_prefix("///"))
                .or_else(|| t.strip_prefix("//"))
                .unwrap_or(l)
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// One quote of a report cell found in a text: `` <value> (report: `<row>`, <column>) ``.
#[derive(Clone, Debug, PartialEq)]
pub struct Quote {
    /// The value as quoted (including a unit such as `%`).
    pub value: String,
    /// The row (kernel name).
    pub row: String,
    /// The column name.
    pub column: String,
}

/// Every quote in `text`. The value is the run of non-space characters before ` (report: `,
/// plus a trailing `%` or `ns` unit when the number and unit are separated by one space.
pub fn quotes(text: &str) -> Vec<Quote> {
    let mut out = vec![];
    let key = " (report: `";
    let mut from = 0;
    while let Some(i) = text[from..].find(key) {
        let at = from + i;
        let before = &text[..at];
        let mut words = before.rsplit(|c: char| c.is_whitespace());
        let last = words.next().unwrap_or("");
        let value = if last == "%" || last == "ns" {
            format!("{} {last}", words.next().unwrap_or(""))
        } else {
            last.to_string()
        };
        let rest = &text[at + key.len()..];
        let Some(rq) = rest.find('`') else { break };
        let row = rest[..rq].split_whitespace().collect::<Vec<_>>().join(" ");
        let after = &rest[rq + 1..];
        let column = after
            .trim_start_matches(',')
            .trim_start()
            .split(')')
            .next()
            .unwrap_or("")
            .split_whitespace()
            .collect::<Vec<_>>()
            .join(" ");
        out.push(Quote { value, row, column });
        from = at + key.len();
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn later_tables_can_be_quoted() {
        let md = "build: AVX2;\n\n| kernel | ns/test |\n|---|---|\n| a | 0.5 |\n\nSpheres:\n\n| sphere kernel | ns/test | x |\n|---|---|---|\n| s, 8 lanes | 1.8 | y |\n";
        let r = Report::parse(md).unwrap();
        assert_eq!(r.rows.len(), 1);
        assert_eq!(r.number("s, 8 lanes", "ns/test"), Some(1.8));
        assert_eq!(r.cell("s, 8 lanes", "x"), Some("y"));
        assert_eq!(r.cell("a", "x"), None);
        assert!(Report::parse("| a | b |\n|---|---|\n| 1 |\n").is_err());
    }

    #[test]
    fn parses_a_table_and_finds_quotes() {
        let md = "Machine: x; build: AVX2; workload\n\n| kernel | ns/test | crack rate |\n|---|---|---|\n| a, 8 lanes | 0.5 | 1.540 % |\n| b | 2.0 | 0.000 % |\n";
        let r = Report::parse(md).unwrap();
        assert_eq!(r.build(), "AVX2");
        assert_eq!(r.cell("a, 8 lanes", "crack rate"), Some("1.540 %"));
        assert_eq!(r.number("b", "ns/test"), Some(2.0));
        assert_eq!(r.cell("c", "ns/test"), None);
        let src = "//! lets 1.540 % (report: `a, 8 lanes`, crack\n//! rate) escape; 0.5 (report: `a, 8 lanes`, ns/test).";
        let q = quotes(&prose(src));
        assert_eq!(q.len(), 2);
        assert_eq!(
            (q[0].value.as_str(), q[0].row.as_str(), q[0].column.as_str()),
            ("1.540 %", "a, 8 lanes", "crack rate")
        );
        assert_eq!(
            (q[1].value.as_str(), q[1].column.as_str()),
            ("0.5", "ns/test")
        );
    }
}
