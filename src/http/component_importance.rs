//! `POST /v1/component-importance`: fault-propagation importance of machine components.

use axum::extract::State;
use axum::response::Response;

use super::{ApiError, AppState, ProblemResponses, Valid, run_calc};
use crate::calc::component_importance::{
    self, ComponentImportanceInput, ComponentImportanceRequest, ComponentImportanceResponse,
};

/// Rank machine components by how far and how harmfully their faults spread at given ages.
///
/// A directed "fault of A causes fault of B" graph is turned into edge influences (betweenness
/// over all simple paths, node efficiency, ISM hierarchy weights); each component's Weibull
/// failure probability F(t) and failure-mode risk RI(t) [1/h] are propagated along all simple
/// paths of length ≤ K; the two indices are merged with variable (harmonic) weights into the
/// comprehensive importance CI(t) and ranked, for every requested time. Times in hours.
/// Exact and polynomial on acyclic graphs; on cyclic graphs the simple-path enumeration is
/// budgeted (422 `SIMPLE_PATH_BUDGET_EXCEEDED` names the cheaper alternatives).
#[utoipa::path(
    post,
    path = "/v1/component-importance",
    tag = "reliability",
    operation_id = "compute_component_importance",
    request_body = ComponentImportanceRequest,
    responses(
        (status = 200, description = "CI and ranking per time, with the requested indices, reliability, structure and centralities", body = ComponentImportanceResponse),
        ProblemResponses
    )
)]
pub async fn rank(
    State(state): State<AppState>,
    Valid { input, limit, .. }: Valid<ComponentImportanceRequest, ComponentImportanceInput>,
) -> Result<Response, ApiError> {
    run_calc(&state, limit, move |budget| {
        component_importance::run_valid(&input, budget)
    })
    .await
}
