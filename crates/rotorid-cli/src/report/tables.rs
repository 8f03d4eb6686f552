//! The report's tables as formatted text, shared by the markdown and HTML documents: one
//! table per speed case with, per parameter and direction, the true value, then for each
//! setting the estimate at 0.3 s, its relative error and identification time (1 %), and
//! the paper's reported time; and one summary sentence per case and setting.

use serde::Serialize;

use super::format;
use super::results::Row;
use super::Report;

/// One line of the attribution table: a combination of data and rule.
#[derive(Debug, Clone, Serialize)]
pub struct AttributionRow {
    /// `Newmark` or `exact`.
    pub data: String,
    /// The rule's name.
    pub rule: String,
    /// e.g. `c_z -5.26e-3`.
    pub worst_error: String,
    /// e.g. `2.19 %`.
    pub worst_share: String,
}

/// The attribution table of one case.
#[derive(Debug, Clone, Serialize)]
pub struct AttributionTable {
    /// e.g. `Constant speed 1200 rpm`.
    pub title: String,
    /// Four lines: paper's setting, the two cross combinations, ours.
    pub rows: Vec<AttributionRow>,
}

/// One attribution table per case (module doc of [`super::results::Attribution`]).
pub fn attribution_tables(report: &Report) -> Vec<AttributionTable> {
    report
        .cases
        .iter()
        .map(|case| AttributionTable {
            title: capitalised(case.description),
            rows: report
                .attribution
                .iter()
                .filter(|a| a.case == case.name)
                .map(|a| AttributionRow {
                    data: a.simulation.clone(),
                    rule: a.quadrature.to_string(),
                    worst_error: format!(
                        "{} {}",
                        a.worst_parameter,
                        format::rel_error(Some(a.worst_relative_error).filter(|e| e.is_finite()))
                    ),
                    worst_share: format::percent(a.worst_share_outside),
                })
                .collect(),
        })
        .collect()
}

fn capitalised(s: &str) -> String {
    let mut c = s.chars();
    c.next()
        .map_or_else(String::new, |f| f.to_uppercase().chain(c).collect())
}

/// One table line.
#[derive(Debug, Clone, Serialize)]
pub struct TableRow {
    /// e.g. `m (x)`.
    pub parameter: String,
    /// Unit, e.g. `N s/m`.
    pub unit: String,
    /// True value.
    pub truth: String,
    /// Paper's setting: estimate, relative error, identification time.
    pub paper: [String; 3],
    /// Our setting: estimate, relative error, identification time.
    pub ours: [String; 3],
    /// The paper's claim, e.g. `< 0.2 s`.
    pub claim: String,
    /// Whether each setting meets the claim.
    pub meets: [bool; 2],
}

/// One speed case's table.
#[derive(Debug, Clone, Serialize)]
pub struct CaseTable {
    /// e.g. `Constant speed 1200 rpm (paper figs. 2-5)`.
    pub title: String,
    /// Six lines.
    pub rows: Vec<TableRow>,
    /// One sentence per setting.
    pub summary: Vec<String>,
}

fn find<'a>(report: &'a Report, case: &str, setting: &str, name: &str) -> Option<&'a Row> {
    report
        .rows
        .iter()
        .find(|r| r.case == case && r.setting == setting && r.name == name)
}

fn cells(r: Option<&Row>) -> [String; 3] {
    match r {
        Some(r) => [
            format::opt_value(r.estimate),
            format::rel_error(r.relative_error),
            format::time(r.identification_time),
        ],
        None => ["\u{2014}".into(), "\u{2014}".into(), "\u{2014}".into()],
    }
}

/// The tables of `report`, one per case, in the report's case order.
pub fn case_tables(report: &Report) -> Vec<CaseTable> {
    let names = ["m_x", "m_z", "c_x", "c_z", "k_x", "k_z"];
    report
        .cases
        .iter()
        .map(|case| {
            let mut rows = Vec::new();
            for name in names {
                let p = find(report, case.name, "paper", name);
                let o = find(report, case.name, "ours", name);
                let Some(any) = p.or(o) else { continue };
                rows.push(TableRow {
                    parameter: format!("{} ({})", any.parameter, any.direction),
                    unit: any.unit.to_string(),
                    truth: format::value(any.true_value),
                    paper: cells(p),
                    ours: cells(o),
                    claim: format!("< {} s", any.paper_time),
                    meets: [
                        p.is_some_and(|r| r.within_paper_time),
                        o.is_some_and(|r| r.within_paper_time),
                    ],
                });
            }
            let summary = report
                .settings
                .iter()
                .map(|s| summary(report, case.name, s.name, &s.description))
                .collect();
            let f = case.paper_figures;
            CaseTable {
                title: format!(
                    "{} (paper figs. {}-{})",
                    capitalised(case.description),
                    f[0],
                    f[3]
                ),
                rows,
                summary,
            }
        })
        .collect()
}

/// e.g. "paper's setting: 6 of 6 parameters within 1 % of the truth by the paper's times;
/// slowest c_z at 0.1234 s; largest error at 0.3 s: c_x +1.2e-3."
fn summary(report: &Report, case: &str, setting: &str, description: &str) -> String {
    let rows: Vec<&Row> = report
        .rows
        .iter()
        .filter(|r| r.case == case && r.setting == setting)
        .collect();
    let met = rows.iter().filter(|r| r.within_paper_time).count();
    let never: Vec<&str> = rows
        .iter()
        .filter(|r| r.identification_time.is_none())
        .map(|r| r.name)
        .collect();
    let slowest = rows
        .iter()
        .filter_map(|r| r.identification_time.map(|t| (t, r.name)))
        .max_by(|a, b| a.0.total_cmp(&b.0));
    let worst = rows
        .iter()
        .filter_map(|r| r.relative_error.map(|e| (e, r.name)))
        .max_by(|a, b| a.0.abs().total_cmp(&b.0.abs()));
    let mut s = format!(
        "{description}: {met} of {} parameters stay within 1 % of the true value from before the \
         paper's reported time",
        rows.len()
    );
    if let Some((t, name)) = slowest {
        s += &format!("; the slowest is {name} at {}", format::time(Some(t)));
    }
    if !never.is_empty() {
        s += &format!(
            "; not within 1 % at the end of the record: {}",
            never.join(", ")
        );
    }
    let spiky: Vec<String> = rows
        .iter()
        .filter(|r| r.outside_after_paper_time > 0.0)
        .map(|r| format!("{} {}", r.name, format::percent(r.outside_after_paper_time)))
        .collect();
    if !spiky.is_empty() {
        s += &format!(
            "; share of instants after the paper's time outside 1 % (isolated spikes): {}",
            spiky.join(", ")
        );
    }
    if let Some((e, name)) = worst {
        s += &format!(
            "; largest relative error at {} s: {name} {}",
            report.estimate_time,
            format::rel_error(Some(e))
        );
    }
    s + "."
}
