//! `POST /v1/machining-size/train`, `/predict` and `/analyze`: gradient-boosted trees of machined
//! dimensions with XGBoost's semantics, exact SHAP explanations and the paper's data diagnostics.

use axum::extract::State;
use axum::response::Response;

use super::{ApiError, AppState, ProblemResponses, Valid, run_calc};
use crate::calc::machining_size::{
    self, AnalyzeInput, AnalyzeRequest, AnalyzeResponse, PredictInput, PredictRequest,
    PredictResponse, TrainInput, TrainRequest, TrainResponse,
};

/// Train a gradient-boosted tree model of a machined dimension.
///
/// XGBoost's squared-error semantics (exact or hist split search, L1/L2 leaf regularisation, γ
/// pruning with the un-halved loss change, seeded column and row sampling) on the centred target
/// in f64. Returns the model as JSON (send it to `/predict`), training, holdout and optional
/// k-fold metrics (MAE, MSE, RMSE, R²), importances and an optional SHAP summary. Runs on the
/// compute pool; the time budget is checked before every boosting round and the report says how
/// training stopped.
#[utoipa::path(
    post,
    path = "/v1/machining-size/train",
    tag = "machining-size",
    operation_id = "train_machining_size",
    request_body = TrainRequest,
    responses(
        (status = 200, description = "The model, its metrics and the optional outputs", body = TrainResponse),
        ProblemResponses
    )
)]
pub async fn train(
    State(state): State<AppState>,
    Valid { input, limit, .. }: Valid<TrainRequest, TrainInput>,
) -> Result<Response, ApiError> {
    run_calc(&state, limit, move |budget| {
        machining_size::run_train_valid(&input, budget)
    })
    .await
}

/// Predict with a model (ours or an XGBoost JSON model) and explain the predictions.
///
/// Routing is bit-for-bit XGBoost's for imported models (rows rounded to f32, f32 thresholds).
/// Optional path-dependent or interventional SHAP values and interaction values, with local
/// accuracy (φ₀ + Σφ = prediction) checked on every row. Malformed or hostile model documents are
/// rejected with the pointer of the defect.
#[utoipa::path(
    post,
    path = "/v1/machining-size/predict",
    tag = "machining-size",
    operation_id = "predict_machining_size",
    request_body = PredictRequest,
    responses(
        (status = 200, description = "Predictions and the optional SHAP and interaction values", body = PredictResponse),
        ProblemResponses
    )
)]
pub async fn predict(
    State(state): State<AppState>,
    Valid { input, limit, .. }: Valid<PredictRequest, PredictInput>,
) -> Result<Response, ApiError> {
    run_calc(&state, limit, move |budget| {
        machining_size::run_predict_valid(&input, budget)
    })
    .await
}

/// Data diagnostics of the paper: constant columns, PCA, grey relational grades, SMOGN preview.
///
/// Constant columns always; PCA contribution rates and composite scores, grey relational grades
/// against the target and a SMOGN resampling preview when asked.
#[utoipa::path(
    post,
    path = "/v1/machining-size/analyze",
    tag = "machining-size",
    operation_id = "analyze_machining_size",
    request_body = AnalyzeRequest,
    responses(
        (status = 200, description = "The diagnostics asked for", body = AnalyzeResponse),
        ProblemResponses
    )
)]
pub async fn analyze(
    State(state): State<AppState>,
    Valid { input, limit, .. }: Valid<AnalyzeRequest, AnalyzeInput>,
) -> Result<Response, ApiError> {
    run_calc(&state, limit, move |budget| {
        machining_size::run_analyze_valid(&input, budget)
    })
    .await
}
