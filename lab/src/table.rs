//! Tables of text cells, printed aligned for a terminal or as Markdown (`umbra inspect`'s views,
//! the stability summary).

/// A table: header and rows, printed aligned (text) or as Markdown.
pub struct Table {
    head: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Table {
    /// A table with these column headers.
    pub fn new(head: &[&str]) -> Self {
        Self {
            head: head.iter().map(|s| s.to_string()).collect(),
            rows: Vec::new(),
        }
    }

    /// Appends a row (one cell per column).
    pub fn row(&mut self, r: Vec<String>) {
        self.rows.push(r);
    }

    /// The table as aligned text (`md` = false) or as a Markdown table.
    pub fn render(&self, md: bool) -> String {
        let mut out = String::new();
        if md {
            out += &format!("| {} |\n", self.head.join(" | "));
            out += &format!("|{}\n", "---|".repeat(self.head.len()));
            for r in &self.rows {
                out += &format!("| {} |\n", r.join(" | "));
            }
            return out;
        }
        let n = self.head.len();
        let mut w = vec![0usize; n];
        for r in std::iter::once(&self.head).chain(&self.rows) {
            for (i, c) in r.iter().enumerate().take(n) {
                w[i] = w[i].max(c.chars().count());
            }
        }
        let line = |r: &Vec<String>| {
            r.iter()
                .enumerate()
                .map(|(i, c)| format!("{c:<width$}", width = w[i]))
                .collect::<Vec<_>>()
                .join("  ")
                .trim_end()
                .to_string()
        };
        out += &line(&self.head);
        out.push('\n');
        out += &w
            .iter()
            .map(|k| "-".repeat(*k))
            .collect::<Vec<_>>()
            .join("  ");
        out.push('\n');
        for r in &self.rows {
            out += &line(r);
            out.push('\n');
        }
        out
    }
}
