//! The one place that builds the wire response of `POST /v1/component-importance` from the
//! domain output: component ids back on edge values, the optional groups the request asked for
//! (omitted otherwise), warnings, and the graph facts and cost in `meta`.

use std::time::Instant;

use super::compute::ComponentImportanceOutput;
use super::input::{ComponentImportanceInput, Finding};
use super::wire::{
    Centralities, ComponentImportanceResponse, EdgeValue, KendallTau, Matrices, Meta, TailBound,
    TimeResult, Warning,
};
use crate::numerics::{SolverReport, StopReason};

fn warning(f: Finding) -> Warning {
    Warning {
        code: f.code,
        detail: f.detail,
        pointer: f.pointer,
    }
}

fn edge_values(input: &ComponentImportanceInput, values: &[f64]) -> Vec<EdgeValue> {
    let g = &input.graph;
    input
        .edge_csr
        .iter()
        .map(|&e| EdgeValue {
            from: input.ids[g.tail(e)].clone(),
            to: input.ids[g.head(e)].clone(),
            value: values[e],
        })
        .collect()
}

/// Builds the response: ids back on edges, the optional groups the request asked for, the
/// warnings and the cost (`started`: when the request was taken up, before validation).
#[must_use]
pub fn respond(
    input: &ComponentImportanceInput,
    out: ComponentImportanceOutput,
    started: Instant,
) -> ComponentImportanceResponse {
    let flags = input.outputs;
    let st = &out.structure;
    let matrices = flags.matrices.then(|| Matrices {
        edge_betweenness: edge_values(input, &st.betweenness),
        efficiency: st.efficiency.clone(),
        levels: st.levels.h.clone(),
        level_weights: st.level_weights.clone(),
        t: st.t.clone(),
        hc: edge_values(input, &st.hc),
        he: edge_values(input, &st.he),
        he_diag_display: st.he_diag_display.clone(),
    });
    let centralities = out.centralities.as_ref().map(|c| Centralities {
        out_degree: c.out_degree.clone(),
        in_degree: c.in_degree.clone(),
        betweenness: c.betweenness.clone(),
        closeness_out: c.closeness_out.clone(),
        pagerank_reversed: c.pagerank_reversed.clone(),
    });
    let results = out
        .times
        .into_iter()
        .enumerate()
        .map(|(ti, t)| {
            let kendall_tau_b = out.centralities.as_ref().map(|c| {
                let [a, b, d, e, f] = c.tau_b[ti];
                KendallTau {
                    out_degree: a,
                    in_degree: b,
                    betweenness: d,
                    closeness_out: e,
                    pagerank_reversed: f,
                }
            });
            let ind = flags.indices;
            let rel = flags.reliability;
            TimeResult {
                time_h: t.time_h,
                tail_bound: ind.then_some(TailBound {
                    probability: t.probability.tail_bound,
                    risk: t.risk.tail_bound,
                }),
                fp_probability_raw: if ind { t.probability.raw } else { None },
                fp_risk_raw: if ind { t.risk.raw } else { None },
                fp_probability: ind.then_some(t.probability.fp),
                fp_risk: ind.then_some(t.risk.fp),
                weights_probability: ind.then_some(t.weights_probability),
                weights_risk: ind.then_some(t.weights_risk),
                f: rel.then_some(t.f),
                lambda_per_h: rel.then_some(t.lambda),
                ri_per_h: rel.then_some(t.ri),
                ci: t.ci,
                rank: t.rank,
                kendall_tau_b,
            }
        })
        .collect();
    let elapsed_ms = started.elapsed().as_secs_f64() * 1e3;
    ComponentImportanceResponse {
        components: input.ids.clone(),
        results,
        warnings: out.warnings.into_iter().map(warning).collect(),
        meta: Meta {
            is_dag: out.is_dag,
            n: input.graph.n(),
            m: input.graph.m(),
            n_levels: st.levels.n_levels,
            longest_path_edges: out.longest_path_edges,
            simple_paths_enumerated: out.work.paths,
            betweenness: input.betweenness,
            betweenness_algorithm: out.betweenness_algorithm.label().to_owned(),
            propagation_algorithm: out.propagation_algorithm.label().to_owned(),
            path_cap: u32::try_from(input.path_cap).unwrap_or(u32::MAX),
            constant_weights: out.constant_weights,
            report: SolverReport {
                stop_reason: StopReason::Completed,
                iterations: out.work.passes,
                evaluations: out.work.paths,
                elapsed_ms,
            },
            elapsed_ms,
        },
        matrices,
        centralities,
    }
}
