//! The compute pool: admission, queueing, lanes, budgets and cancellation for every calculation.
//!
//! * **Heavy lane.** Calculations run on the process's one rayon pool (sized by
//!   `--compute-threads`), at most `slots` at once, with at most `queue_depth` more waiting; beyond
//!   that a request is refused with 503 + `Retry-After`. The `Retry-After` value is the real
//!   backlog: jobs ahead × the recent mean job time / slots. A request whose expected wait already
//!   exceeds its time budget is refused at once instead of after waiting for nothing.
//! * **Fair queue.** Waiting heavy jobs sit in one queue per client (API key id, or remote
//!   address without keys) and a freed slot goes to the waiting client that started a job least
//!   recently (round-robin when all wait), so a client with one job waits about one running job
//!   per other busy client, never behind another client's whole backlog. A client may have at most `client_queue_depth` jobs waiting (beyond: 429
//!   `CLIENT_QUEUE_FULL`, its own backlog, other clients unaffected); when the whole queue is full,
//!   a client with a shorter queue takes the place of the newest job of the longest one (which
//!   gets 503), so the room is shared too.
//! * **Cheap lane.** Requests known to be cheap (a closed-form evaluation: the route's recent jobs
//!   took well under a millisecond of CPU and the body is small) do not queue behind sweeps: they
//!   are classified by the CPU time their jobs took, not by wall time, so a loaded machine that
//!   stretches them does not push them into the heavy queue; they run on
//!   a small separate lane (twice the slots at once, on tokio's blocking threads), or, below half a
//!   millisecond, inline on the thread serving the request (at most cores − 1 at once, so one
//!   connection thread is always free). Their CPU is bounded by that lane's size × their (short)
//!   duration.
//! * **Budget.** Each job receives a [`Budget`]: the request's own time limit (capped by the
//!   server's maximum) counted from the request's arrival, so queueing spends it too; the threads
//!   its parallel parts may use (`--threads-per-job`, on the same rayon pool); and a cancellation
//!   flag raised when the request is dropped (the client went away) or the service's shutdown
//!   deadline passes, so the job stops at its next budget check and frees its slot.
//! * A panic inside a job is logged and becomes a 500 whose body does not echo it.

use std::collections::{HashMap, VecDeque};
use std::panic::AssertUnwindSafe;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, Weak};
use std::time::{Duration, Instant};

use tokio::sync::{OwnedSemaphorePermit, Semaphore};

use crate::numerics::Budget;

use super::problem::ApiError;

/// A route whose recent jobs took less than this (mean) is served on the cheap lane.
const CHEAP_JOB: Duration = Duration::from_millis(2);
/// A cheap route whose recent jobs took less than this runs inline, on the thread that serves the
/// request (no hand-off to another thread: the hand-off alone costs tens of microseconds).
const INLINE_JOB: Duration = Duration::from_micros(500);
/// Bodies above this size never take the cheap lane (decoding alone may take milliseconds).
const CHEAP_BODY_BYTES: usize = 64 * 1024;
/// Weight of the newest observation in the running mean of job times.
const EWMA_WEIGHT: f64 = 0.2;
/// The client of a request that came with no remote address and no key (in-process calls).
const LOCAL_CLIENT: &str = "local";

/// What a handler knows about a request before it is queued.
#[derive(Debug, Clone, Default)]
pub struct Demand {
    /// The request's own time limit (`time_limit_ms`), if it gives one.
    pub time_limit: Option<Duration>,
    /// The module's estimate of the work, if it has one.
    pub cost: Cost,
}

/// A module's estimate of a request's work.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Cost {
    /// Unknown: the lane is chosen from the route's recent job times and the body size.
    #[default]
    Unknown,
    /// Closed form, sub-millisecond: always the cheap lane.
    Cheap,
    /// Iterative or swept work: always the heavy lane.
    Heavy,
}

impl From<Option<Duration>> for Demand {
    fn from(time_limit: Option<Duration>) -> Self {
        Self {
            time_limit,
            cost: Cost::Unknown,
        }
    }
}

tokio::task_local! {
    /// The matched route and body size of the request being served (set by the request layer),
    /// so the pool can learn per-route job times without every handler passing them.
    pub static REQUEST_INFO: RequestInfo;
}

/// Route and body size of the request in flight, and where its progress goes.
#[derive(Clone, Default)]
pub struct RequestInfo {
    /// The matched route (e.g. `/v1/cognates`), or empty.
    pub route: String,
    /// Declared body size \[bytes\], if known.
    pub body_bytes: usize,
    /// Progress sink of a streaming request (`Accept: text/event-stream`).
    pub progress: Option<Arc<crate::numerics::budget::ProgressSink>>,
    /// Who the request belongs to for fair queueing: its API key id, else its remote address
    /// (set by [`crate::http::auth::authenticate`]); empty means in-process.
    pub client: Arc<str>,
    /// Time the door took on this request (typed parse, per-field rules, rules between fields)
    /// \[ns\], 0 until it ran: reported as `door` in `Server-Timing`.
    pub door_ns: Arc<AtomicU64>,
}

/// Where a job runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Lane {
    /// On the thread serving the request (sub-millisecond jobs).
    Inline,
    /// On the cheap lane (tokio's blocking threads, `cheap` permits).
    Cheap,
    /// On the rayon compute pool behind the admission semaphore.
    Heavy,
}

/// Semaphore-bounded access to the compute pool.
#[derive(Clone)]
pub struct ComputePool {
    inner: Arc<Inner>,
}

struct Inner {
    /// The heavy lane's slots and per-client queues.
    fair: Mutex<Fair>,
    n_slots: usize,
    cheap: Arc<Semaphore>,
    /// Jobs running inline on the connection threads at once (always leaves one thread free).
    inline: Arc<Semaphore>,
    queue_depth: usize,
    client_queue_depth: AtomicUsize,
    max_budget: Duration,
    threads_per_job: AtomicUsize,
    /// Recent mean job CPU time per route [µs] (lane choice).
    route_us: Mutex<HashMap<String, f64>>,
    /// Recent mean heavy-lane job time [µs], for the backlog estimate.
    heavy_mean_us: AtomicU64,
    /// Cancellation flags of running jobs (weak: a finished job's flag is gone).
    running: Mutex<Vec<Weak<AtomicBool>>>,
    stopping: AtomicBool,
}

/// Free heavy slots and the jobs waiting for one, a FIFO queue per client.
#[derive(Default)]
struct Fair {
    free: usize,
    queues: HashMap<Arc<str>, VecDeque<Waiter>>,
    /// Clients with a waiting job, in the order they queued (ties of `served`).
    rotation: VecDeque<Arc<str>>,
    /// When each client last started a job (a sequence number; absent = never): the waiting
    /// client served least recently goes first, so a client whose job took a free slot directly
    /// does not also take the next freed one ahead of a client that has waited.
    served: HashMap<Arc<str>, u64>,
    serve_seq: u64,
    waiting: usize,
    next_ticket: u64,
}

struct Waiter {
    ticket: u64,
    tx: tokio::sync::oneshot::Sender<Slot>,
}

impl Fair {
    fn set_gauge(&self) {
        metrics::gauge!("mechcalc_queue_waiting").set(self.waiting as f64);
    }

    /// Jobs a new job of `client` would wait behind: its own queue, and from every other client
    /// as many as the round-robin serves before it.
    fn ahead(&self, client: &str) -> usize {
        let own = self.queues.get(client).map_or(0, VecDeque::len);
        own + self
            .queues
            .iter()
            .filter(|(c, _)| &***c != client)
            .map(|(_, q)| q.len().min(own + 1))
            .sum::<usize>()
    }

    /// Record that `client` starts a job now.
    fn mark_served(&mut self, client: &Arc<str>) {
        self.serve_seq += 1;
        self.served.insert(Arc::clone(client), self.serve_seq);
        // Forget clients that have nothing waiting once the table grows (a forgotten client
        // counts as never served: at most one early start for it).
        if self.served.len() > 4096 {
            let queues = &self.queues;
            self.served.retain(|c, _| queues.contains_key(c));
        }
    }

    /// The next waiting job: the oldest of the waiting client served least recently (queue order
    /// among equals), removed from its queue. With every client waiting this is round-robin.
    fn pop_next(&mut self) -> Option<Waiter> {
        let pos = self
            .rotation
            .iter()
            .enumerate()
            .min_by_key(|(i, c)| (self.served.get(*c).copied().unwrap_or(0), *i))
            .map(|(i, _)| i)?;
        let client = self.rotation.remove(pos)?;
        let queue = self.queues.get_mut(&client)?;
        let w = queue.pop_front();
        if queue.is_empty() {
            self.queues.remove(&client);
        } else {
            self.rotation.push_back(Arc::clone(&client));
        }
        if w.is_some() {
            self.waiting -= 1;
            self.mark_served(&client);
        }
        w
    }

    /// Remove the waiting job `ticket` of `client` (it gave up); false when it is not waiting.
    fn remove(&mut self, client: &str, ticket: u64) -> bool {
        let Some(queue) = self.queues.get_mut(client) else {
            return false;
        };
        let Some(pos) = queue.iter().position(|w| w.ticket == ticket) else {
            return false;
        };
        queue.remove(pos);
        if queue.is_empty() {
            self.queues.remove(client);
            self.rotation.retain(|c| &**c != client);
        }
        self.waiting -= 1;
        true
    }

    /// Drop the newest waiting job of the client with the longest queue, if that queue is longer
    /// than `than + 1` (Longest Queue Drop: the room of a full queue is shared); its request gets
    /// 503.
    fn displace_longest(&mut self, than: usize) -> bool {
        let Some(longest) = self
            .queues
            .iter()
            .max_by_key(|(_, q)| q.len())
            .map(|(c, q)| (Arc::clone(c), q.len()))
        else {
            return false;
        };
        if longest.1 <= than + 1 {
            return false;
        }
        if let Some(q) = self.queues.get_mut(&longest.0) {
            q.pop_back();
            self.waiting -= 1;
            metrics::counter!("mechcalc_rejected_total", "cause" => "displaced").increment(1);
            return true;
        }
        false
    }
}

/// A heavy-lane slot; dropping it hands it to the next waiting job in round-robin order.
pub struct Slot {
    pool: Option<Arc<Inner>>,
}

impl std::fmt::Debug for Slot {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Slot")
    }
}

impl Drop for Slot {
    fn drop(&mut self) {
        let Some(inner) = self.pool.take() else {
            return;
        };
        let Ok(mut fair) = inner.fair.lock() else {
            return;
        };
        while let Some(w) = fair.pop_next() {
            let slot = Slot {
                pool: Some(Arc::clone(&inner)),
            };
            match w.tx.send(slot) {
                Ok(()) => {
                    fair.set_gauge();
                    return;
                }
                // The waiter is gone (timed out or its client left): disarm and try the next.
                Err(mut unsent) => drop(unsent.pool.take()),
            }
        }
        fair.free += 1;
        fair.set_gauge();
    }
}

/// What a job holds while it runs: a heavy slot or a permit of the cheap or inline lane.
enum Held {
    Slot(#[expect(dead_code, reason = "held for its Drop")] Slot),
    Permit(#[expect(dead_code, reason = "held for its Drop")] OwnedSemaphorePermit),
}

/// Takes a waiting job out of its queue however the wait ends (timeout, client gone).
struct WaitGuard<'a> {
    inner: &'a Inner,
    client: Arc<str>,
    ticket: u64,
}

impl Drop for WaitGuard<'_> {
    fn drop(&mut self) {
        if let Ok(mut fair) = self.inner.fair.lock()
            && fair.remove(&self.client, self.ticket)
        {
            fair.set_gauge();
        }
    }
}

/// Raises the job's cancellation flag when the request is dropped before the job finished.
struct CancelOnDrop {
    flag: Arc<AtomicBool>,
    done: bool,
}

impl Drop for CancelOnDrop {
    fn drop(&mut self) {
        if !self.done {
            self.flag.store(true, Ordering::Relaxed);
            metrics::counter!("mechcalc_jobs_cancelled_total", "cause" => "client_gone")
                .increment(1);
            tracing::warn!(
                "client went away; the running job is cancelled at its next budget check"
            );
        }
    }
}

impl ComputePool {
    /// A pool with `slots` concurrent heavy jobs, `queue_depth` waiters and a server-wide budget
    /// cap; each job may use every thread of the rayon pool for its parallel parts; the cheap lane
    /// runs as many jobs at once as there are slots, times two.
    #[must_use]
    pub fn new(slots: usize, queue_depth: usize, max_budget: Duration) -> Self {
        let slots = slots.max(1);
        Self {
            inner: Arc::new(Inner {
                fair: Mutex::new(Fair {
                    free: slots,
                    ..Fair::default()
                }),
                n_slots: slots,
                cheap: Arc::new(Semaphore::new(2 * slots)),
                inline: Arc::new(Semaphore::new(
                    std::thread::available_parallelism()
                        .map_or(1, std::num::NonZeroUsize::get)
                        .saturating_sub(1)
                        .max(1),
                )),
                queue_depth,
                client_queue_depth: AtomicUsize::new((queue_depth / 2).max(1)),
                max_budget,
                threads_per_job: AtomicUsize::new(rayon::current_num_threads()),
                route_us: Mutex::new(HashMap::new()),
                heavy_mean_us: AtomicU64::new(0),
                running: Mutex::new(Vec::new()),
                stopping: AtomicBool::new(false),
            }),
        }
    }

    /// The same pool with `threads` threads per job for parallel parts (at least 1).
    #[must_use]
    pub fn with_threads_per_job(self, threads: usize) -> Self {
        self.inner
            .threads_per_job
            .store(threads.max(1), Ordering::Relaxed);
        self
    }

    /// The same pool with at most `depth` waiting heavy jobs per client (at least 1).
    #[must_use]
    pub fn with_client_queue_depth(self, depth: usize) -> Self {
        self.inner
            .client_queue_depth
            .store(depth.max(1), Ordering::Relaxed);
        self
    }

    /// Threads one job may use for its parallel parts.
    #[must_use]
    pub fn threads_per_job(&self) -> usize {
        self.inner.threads_per_job.load(Ordering::Relaxed)
    }

    /// The server-wide cap on a job's time budget.
    #[must_use]
    pub fn max_budget(&self) -> Duration {
        self.inner.max_budget
    }

    /// Heavy-lane slots free right now.
    #[must_use]
    pub fn available_slots(&self) -> usize {
        self.inner.fair.lock().map_or(0, |f| f.free)
    }

    /// Heavy-lane slots in all.
    #[must_use]
    pub fn slots(&self) -> usize {
        self.inner.n_slots
    }

    /// Requests waiting for a heavy-lane slot right now.
    #[must_use]
    pub fn waiting(&self) -> usize {
        self.inner.fair.lock().map_or(0, |f| f.waiting)
    }

    /// Clients with a heavy job waiting right now.
    #[must_use]
    pub fn waiting_clients(&self) -> usize {
        self.inner.fair.lock().map_or(0, |f| f.queues.len())
    }

    /// Stop taking work and cancel every running job (the shutdown deadline has passed).
    pub fn cancel_all(&self) {
        self.inner.stopping.store(true, Ordering::SeqCst);
        let flags = self
            .inner
            .running
            .lock()
            .map(|mut v| std::mem::take(&mut *v))
            .unwrap_or_default();
        let mut n = 0u64;
        for f in flags.iter().filter_map(Weak::upgrade) {
            f.store(true, Ordering::Relaxed);
            n += 1;
        }
        // Waiting jobs are told at once (their senders are dropped: 503 shutting down).
        if let Ok(mut fair) = self.inner.fair.lock() {
            fair.queues.clear();
            fair.rotation.clear();
            fair.waiting = 0;
            fair.set_gauge();
        }
        metrics::counter!("mechcalc_jobs_cancelled_total", "cause" => "shutdown").increment(n);
        tracing::warn!(jobs = n, "shutdown deadline: running jobs cancelled");
    }

    /// Expected wait for a heavy slot with `ahead` queued jobs ahead and every slot busy [µs]:
    /// the running jobs are on average half done, so they count as half a job each.
    fn expected_wait_us(&self, ahead: usize) -> u64 {
        let mean = self.inner.heavy_mean_us.load(Ordering::Relaxed) as f64;
        let slots = self.inner.n_slots as f64;
        ((ahead as f64 + 0.5 * slots) * mean / slots).round() as u64
    }

    /// Seconds to tell a refused client: the backlog ahead of `ahead` jobs, at least 1.
    fn retry_after_s(&self, ahead: usize) -> u64 {
        self.expected_wait_us(ahead).div_ceil(1_000_000).max(1)
    }

    /// Take a heavy slot for the client of the request in flight (see [`RequestInfo::client`]),
    /// waiting in its queue if there is room; see [`ComputePool::acquire_for`].
    pub async fn acquire(&self, max_wait: Duration) -> Result<Slot, ApiError> {
        let client = REQUEST_INFO
            .try_with(|i| Arc::clone(&i.client))
            .unwrap_or_default();
        self.acquire_for(client, max_wait).await
    }

    /// Take a heavy slot for `client`, waiting in its queue if there is room: 429 when the
    /// client already has its share of waiting jobs; 503 when the whole queue is full (and no
    /// longer queue can give up a place), when the expected wait already exceeds `max_wait`, or
    /// when the wait outlasts it.
    pub async fn acquire_for(
        &self,
        client: Arc<str>,
        max_wait: Duration,
    ) -> Result<Slot, ApiError> {
        let client: Arc<str> = if client.is_empty() {
            Arc::from(LOCAL_CLIENT)
        } else {
            client
        };
        let (rx, ticket) = {
            let Ok(mut fair) = self.inner.fair.lock() else {
                return Err(ApiError::internal());
            };
            if self.inner.stopping.load(Ordering::SeqCst) {
                return Err(ApiError::shutting_down());
            }
            if fair.free > 0 {
                fair.free -= 1;
                fair.mark_served(&client);
                return Ok(Slot {
                    pool: Some(Arc::clone(&self.inner)),
                });
            }
            let own = fair.queues.get(&client).map_or(0, VecDeque::len);
            let cap = self.inner.client_queue_depth.load(Ordering::Relaxed);
            if own >= cap {
                metrics::counter!("mechcalc_rejected_total", "cause" => "client_queue_full")
                    .increment(1);
                let retry = self.retry_after_s(own);
                return Err(ApiError::too_many_requests(
                    "CLIENT_QUEUE_FULL",
                    retry,
                    format!(
                        "this client already has {own} calculations waiting for a compute slot \
                         (at most {cap} per client); retry in {retry} s"
                    ),
                ));
            }
            if fair.waiting >= self.inner.queue_depth && !fair.displace_longest(own) {
                metrics::counter!("mechcalc_rejected_total", "cause" => "queue_full").increment(1);
                return Err(ApiError::overloaded(self.retry_after_s(fair.waiting)));
            }
            let ahead = fair.ahead(&client);
            let wait_us = self.expected_wait_us(ahead);
            let budget_us = u64::try_from(max_wait.as_micros()).unwrap_or(u64::MAX);
            if wait_us > budget_us {
                metrics::counter!("mechcalc_rejected_total", "cause" => "cannot_start_in_time")
                    .increment(1);
                return Err(ApiError::cannot_start_in_time(
                    self.retry_after_s(ahead),
                    wait_us / 1000,
                    budget_us / 1000,
                ));
            }
            let (tx, rx) = tokio::sync::oneshot::channel();
            fair.next_ticket += 1;
            let ticket = fair.next_ticket;
            let queue = fair.queues.entry(Arc::clone(&client)).or_default();
            queue.push_back(Waiter { ticket, tx });
            if queue.len() == 1 {
                fair.rotation.push_back(Arc::clone(&client));
            }
            fair.waiting += 1;
            fair.set_gauge();
            (rx, ticket)
        };
        let guard = WaitGuard {
            inner: &self.inner,
            client,
            ticket,
        };
        let got = tokio::time::timeout(max_wait, rx).await;
        // A slot that arrived just as the wait ended is dropped with `got` and passes on.
        drop(guard);
        match got {
            Ok(Ok(slot)) => Ok(slot),
            Ok(Err(_)) if self.inner.stopping.load(Ordering::SeqCst) => {
                Err(ApiError::shutting_down())
            }
            // Displaced by a client with a shorter queue.
            Ok(Err(_)) => Err(ApiError::overloaded(self.retry_after_s(self.waiting()))),
            Err(_) => {
                metrics::counter!("mechcalc_rejected_total", "cause" => "wait_timeout")
                    .increment(1);
                Err(ApiError::overloaded(self.retry_after_s(self.waiting())))
            }
        }
    }

    /// The lane of a request on `info` with `cost`.
    fn lane(&self, cost: Cost, info: &RequestInfo) -> Lane {
        let recent_us = self
            .inner
            .route_us
            .lock()
            .ok()
            .and_then(|m| m.get(&info.route).copied());
        let small = info.body_bytes <= CHEAP_BODY_BYTES;
        let inline = small && recent_us.is_some_and(|us| us < INLINE_JOB.as_secs_f64() * 1e6);
        match cost {
            Cost::Heavy => Lane::Heavy,
            Cost::Cheap | Cost::Unknown if inline => Lane::Inline,
            Cost::Cheap => Lane::Cheap,
            Cost::Unknown => {
                if small && recent_us.is_some_and(|us| us < CHEAP_JOB.as_secs_f64() * 1e6) {
                    Lane::Cheap
                } else {
                    Lane::Heavy
                }
            }
        }
    }

    /// Learn from a finished job: the route's CPU time per job (lane choice: wall time would
    /// grow with the machine's load and push cheap routes into the heavy queue) and the heavy
    /// lane's wall time per job (backlog estimate).
    fn observe(&self, route: &str, heavy: bool, times: Times) {
        let Times { elapsed, cpu } = times;
        // The job's own thread's CPU (a parallel job also uses others, but then its own share
        // alone is far above the cheap threshold); wall time where the clock is unavailable.
        let cpu_us = if cpu.is_zero() { elapsed } else { cpu }.as_secs_f64() * 1e6;
        if let Ok(mut m) = self.inner.route_us.lock() {
            let e = m.entry(route.to_owned()).or_insert(cpu_us);
            *e += EWMA_WEIGHT * (cpu_us - *e);
        }
        let us = elapsed.as_secs_f64() * 1e6;
        if heavy {
            let old = self.inner.heavy_mean_us.load(Ordering::Relaxed) as f64;
            let new = if old == 0.0 {
                us
            } else {
                old + EWMA_WEIGHT * (us - old)
            };
            self.inner
                .heavy_mean_us
                .store(new.round() as u64, Ordering::Relaxed);
        }
        metrics::histogram!("mechcalc_job_seconds", "route" => route.to_owned(), "lane" => if heavy { "heavy" } else { "cheap" })
            .record(elapsed.as_secs_f64());
    }

    fn register(&self, flag: &Arc<AtomicBool>) {
        if let Ok(mut v) = self.inner.running.lock() {
            v.retain(|w| w.strong_count() > 0);
            v.push(Arc::downgrade(flag));
        }
    }

    /// Run `job` with a budget of the demand's time limit (capped by the server maximum; the
    /// maximum when `None`) counted from now, queueing included: on the cheap lane when the
    /// request is known to be cheap, else on the rayon pool behind the admission semaphore. The
    /// job keeps the caller's tracing span. Dropping the returned future (the client went away)
    /// cancels the job's budget.
    pub async fn run<T, F>(&self, demand: impl Into<Demand>, job: F) -> Result<T, ApiError>
    where
        T: Send + 'static,
        F: FnOnce(&Budget) -> T + Send + 'static,
    {
        let demand = demand.into();
        let arrived = Instant::now();
        let limit = demand
            .time_limit
            .map_or(self.inner.max_budget, |r| r.min(self.inner.max_budget));
        let info = REQUEST_INFO.try_with(Clone::clone).unwrap_or_default();
        let mut lane = self.lane(demand.cost, &info);
        let inline_permit = match lane {
            Lane::Inline => Arc::clone(&self.inner.inline).try_acquire_owned().ok(),
            _ => None,
        };
        if lane == Lane::Inline && inline_permit.is_none() {
            lane = Lane::Cheap;
        }
        let heavy = lane == Lane::Heavy;
        let permit = match (lane, inline_permit) {
            (Lane::Inline, Some(p)) => Held::Permit(p),
            (Lane::Heavy, _) => {
                let client = if info.client.is_empty() {
                    Arc::from(LOCAL_CLIENT)
                } else {
                    Arc::clone(&info.client)
                };
                Held::Slot(self.acquire_for(client, limit).await?)
            }
            // Cheap jobs last microseconds: wait for the cheap lane rather than queue behind
            // sweeps.
            _ => match tokio::time::timeout(limit, Arc::clone(&self.inner.cheap).acquire_owned())
                .await
            {
                Ok(Ok(p)) => Held::Permit(p),
                _ => return Err(ApiError::overloaded(1)),
            },
        };
        let mut cancel = CancelOnDrop {
            flag: Arc::new(AtomicBool::new(false)),
            done: false,
        };
        self.register(&cancel.flag);
        let mut budget = Budget::starting_at(arrived, limit)
            .with_threads(self.threads_per_job())
            .with_cancel_flag(Arc::clone(&cancel.flag));
        if let Some(sink) = &info.progress {
            budget = budget.with_progress(Arc::clone(sink));
        }
        let span = tracing::Span::current();
        let (tx, rx) = tokio::sync::oneshot::channel();
        let gauge = if heavy {
            "mechcalc_heavy_jobs_running"
        } else {
            "mechcalc_cheap_jobs_running"
        };
        metrics::gauge!(gauge).increment(1.0);
        let task = move || {
            let _entered = span.enter();
            let started = Instant::now();
            let cpu0 = thread_cpu();
            let out = std::panic::catch_unwind(AssertUnwindSafe(|| job(&budget)));
            let cpu = thread_cpu().saturating_sub(cpu0);
            let elapsed = started.elapsed();
            let stopped_early = budget.cancelled() || budget.expired();
            drop(permit);
            // The receiver is gone only when the request was dropped; nobody wants the answer.
            let _ = tx.send((out, Times { elapsed, cpu }, stopped_early));
        };
        match lane {
            Lane::Heavy => rayon::spawn(task),
            Lane::Cheap => drop(tokio::task::spawn_blocking(task)),
            Lane::Inline => task(),
        }
        let out = rx.await;
        cancel.done = true;
        metrics::gauge!(gauge).decrement(1.0);
        match out {
            Ok((Ok(v), times, stopped_early)) => {
                self.observe(&info.route, heavy, times);
                if stopped_early {
                    metrics::counter!("mechcalc_budget_stops_total", "route" => info.route.clone())
                        .increment(1);
                }
                Ok(v)
            }
            Ok((Err(payload), _, _)) => {
                tracing::error!(panic = %panic_message(payload), "compute job panicked");
                Err(ApiError::internal())
            }
            Err(_) => {
                tracing::error!("compute job ended without an answer");
                Err(ApiError::internal())
            }
        }
    }
}

/// Wall and CPU time of one job.
#[derive(Debug, Clone, Copy)]
struct Times {
    elapsed: Duration,
    cpu: Duration,
}

/// CPU time the calling thread has used so far (zero where the clock is unavailable).
fn thread_cpu() -> Duration {
    let t = rustix::time::clock_gettime(rustix::time::ClockId::ThreadCPUTime);
    Duration::new(
        u64::try_from(t.tv_sec).unwrap_or(0),
        u32::try_from(t.tv_nsec).unwrap_or(0),
    )
}

/// Lower the calling thread's priority to `nice` (0 to 19; 0 leaves it): the compute pool's
/// start handler, so sweeps yield the CPU to the threads that serve connections and cheap
/// requests. Only ever lowers; failure is logged and harmless.
pub fn lower_thread_priority(nice: i32) {
    if nice <= 0 {
        return;
    }
    if let Err(e) = rustix::process::setpriority_process(None, nice.min(19)) {
        tracing::warn!(error = %e, "cannot lower the compute threads' priority");
    }
}

/// Best-effort text of a panic payload, for the log only.
pub(crate) fn panic_message(payload: Box<dyn std::any::Any + Send>) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_owned()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "non-string panic payload".to_owned()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[tokio::test]
    async fn full_queue_is_503_with_retry_after() {
        let pool = ComputePool::new(1, 0, Duration::from_secs(5));
        let held = pool
            .acquire(Duration::from_millis(10))
            .await
            .expect("first slot is free");
        let err = pool
            .acquire(Duration::from_millis(10))
            .await
            .expect_err("pool is full");
        assert_eq!(err.status().as_u16(), 503);
        drop(held);
        assert!(pool.acquire(Duration::from_millis(10)).await.is_ok());
    }

    #[tokio::test]
    async fn waiter_gets_slot_when_released() {
        let pool = ComputePool::new(1, 1, Duration::from_secs(5));
        let held = pool.acquire(Duration::from_millis(10)).await.expect("free");
        let p2 = pool.clone();
        let waiter = tokio::spawn(async move { p2.acquire(Duration::from_secs(5)).await.is_ok() });
        tokio::time::sleep(Duration::from_millis(20)).await;
        drop(held);
        assert!(waiter.await.expect("join"));
    }

    #[tokio::test]
    async fn budget_is_capped_by_server_max() {
        let pool = ComputePool::new(1, 0, Duration::from_millis(50));
        let remaining = pool
            .run(Some(Duration::from_secs(100)), |b| b.remaining())
            .await
            .expect("runs");
        assert!(remaining <= Duration::from_millis(50));
    }

    #[tokio::test]
    async fn panic_becomes_500() {
        let pool = ComputePool::new(1, 0, Duration::from_secs(1));
        let err = pool
            .run(None, |_| -> u8 { panic!("boom") })
            .await
            .expect_err("panics");
        assert_eq!(err.status().as_u16(), 500);
        assert!(!err.body().detail.contains("boom"));
    }

    #[tokio::test]
    async fn a_dropped_request_cancels_its_job() {
        let pool = ComputePool::new(1, 0, Duration::from_secs(30));
        let (seen_tx, seen_rx) = std::sync::mpsc::channel();
        let fut = pool.run(None, move |b| {
            let t = Instant::now();
            while !b.cancelled() && t.elapsed() < Duration::from_secs(20) {
                std::thread::sleep(Duration::from_millis(1));
            }
            let _ = seen_tx.send(b.cancelled());
        });
        // Let the job start, then drop the request future.
        let _ = tokio::time::timeout(Duration::from_millis(50), fut).await;
        let cancelled = seen_rx
            .recv_timeout(Duration::from_secs(5))
            .expect("the job stops");
        assert!(cancelled);
        // The slot is free again: the job's permit is released just after the job returns (with
        // no queue, an attempt in between is refused at once), so allow it a moment.
        let t = Instant::now();
        let mut freed = false;
        while !freed && t.elapsed() < Duration::from_secs(2) {
            freed = pool.acquire(Duration::from_secs(1)).await.is_ok();
            if !freed {
                tokio::time::sleep(Duration::from_millis(5)).await;
            }
        }
        assert!(
            freed,
            "the cancelled job's slot was not released within 2 s"
        );
    }

    #[tokio::test]
    async fn expected_wait_beyond_the_budget_is_refused_at_once() {
        let pool = ComputePool::new(1, 8, Duration::from_secs(30));
        pool.observe(
            "/x",
            true,
            Times {
                elapsed: Duration::from_secs(2),
                cpu: Duration::from_secs(2),
            },
        );
        let held = pool.acquire(Duration::from_secs(1)).await.expect("free");
        let t = Instant::now();
        let err = pool
            .acquire(Duration::from_millis(500))
            .await
            .expect_err("cannot start within 0.5 s behind a 2 s job");
        assert_eq!(err.status().as_u16(), 503);
        assert!(t.elapsed() < Duration::from_millis(100), "refused at once");
        assert!(err.body().detail.contains("expected wait"));
        drop(held);
    }

    /// Start a waiter of `client` that records the order it got its slot in `order`.
    fn waiter(
        pool: &ComputePool,
        client: &str,
        order: &Arc<Mutex<Vec<String>>>,
    ) -> tokio::task::JoinHandle<bool> {
        let (p, c, o) = (pool.clone(), Arc::<str>::from(client), Arc::clone(order));
        tokio::spawn(async move {
            match p.acquire_for(Arc::clone(&c), Duration::from_secs(5)).await {
                Ok(slot) => {
                    if let Ok(mut v) = o.lock() {
                        v.push(c.to_string());
                    }
                    tokio::time::sleep(Duration::from_millis(5)).await;
                    drop(slot);
                    true
                }
                Err(_) => false,
            }
        })
    }

    #[tokio::test]
    async fn a_second_client_does_not_wait_behind_the_first_clients_backlog() {
        let pool = ComputePool::new(1, 16, Duration::from_secs(30)).with_client_queue_depth(8);
        let held = pool
            .acquire_for(Arc::from("a"), Duration::from_secs(1))
            .await
            .expect("free");
        let order = Arc::new(Mutex::new(Vec::new()));
        let mut tasks = Vec::new();
        for _ in 0..6 {
            tasks.push(waiter(&pool, "a", &order));
            tokio::time::sleep(Duration::from_millis(2)).await;
        }
        tasks.push(waiter(&pool, "b", &order));
        tokio::time::sleep(Duration::from_millis(20)).await;
        assert_eq!(pool.waiting(), 7);
        assert_eq!(pool.waiting_clients(), 2);
        drop(held);
        for t in tasks {
            assert!(t.await.expect("join"), "every waiter got a slot");
        }
        let order = order.lock().expect("order").clone();
        let b_at = order.iter().position(|c| c == "b").expect("b served");
        // a's first job took the free slot: b, never served, takes the next one, then a and b
        // would alternate.
        assert_eq!(b_at, 0, "b served at position {b_at} of {order:?}");
        assert_eq!(pool.waiting(), 0);
        assert_eq!(pool.available_slots(), 1);
    }

    #[tokio::test]
    async fn a_client_over_its_queue_share_gets_429_and_others_still_queue() {
        let pool = ComputePool::new(1, 16, Duration::from_secs(30)).with_client_queue_depth(2);
        let held = pool
            .acquire_for(Arc::from("a"), Duration::from_secs(1))
            .await
            .expect("free");
        let order = Arc::new(Mutex::new(Vec::new()));
        let a1 = waiter(&pool, "a", &order);
        let a2 = waiter(&pool, "a", &order);
        tokio::time::sleep(Duration::from_millis(20)).await;
        let err = pool
            .acquire_for(Arc::from("a"), Duration::from_secs(1))
            .await
            .expect_err("a's share is 2");
        assert_eq!(err.status().as_u16(), 429);
        assert_eq!(err.body().code, "CLIENT_QUEUE_FULL");
        let b = waiter(&pool, "b", &order);
        tokio::time::sleep(Duration::from_millis(20)).await;
        assert_eq!(pool.waiting(), 3);
        drop(held);
        for t in [a1, a2, b] {
            assert!(t.await.expect("join"));
        }
    }

    #[tokio::test]
    async fn a_full_queue_makes_room_for_a_new_client_from_the_longest_queue() {
        let pool = ComputePool::new(1, 3, Duration::from_secs(30)).with_client_queue_depth(3);
        let held = pool
            .acquire_for(Arc::from("a"), Duration::from_secs(1))
            .await
            .expect("free");
        let order = Arc::new(Mutex::new(Vec::new()));
        let a: Vec<_> = (0..3).map(|_| waiter(&pool, "a", &order)).collect();
        tokio::time::sleep(Duration::from_millis(20)).await;
        assert_eq!(pool.waiting(), 3);
        let b = waiter(&pool, "b", &order);
        tokio::time::sleep(Duration::from_millis(20)).await;
        assert_eq!(pool.waiting(), 3, "b took the place of a's newest job");
        drop(held);
        let served_a = futures_util::future::join_all(a)
            .await
            .into_iter()
            .filter(|r| matches!(r, Ok(true)))
            .count();
        assert_eq!(served_a, 2, "one of a's jobs was displaced (503)");
        assert!(b.await.expect("join"));
        // A third client finds the queue full and no queue longer than its own + 1: refused.
        let held = pool
            .acquire_for(Arc::from("a"), Duration::from_secs(1))
            .await
            .expect("free again");
        let w: Vec<_> = ["a", "b", "c"]
            .iter()
            .map(|c| waiter(&pool, c, &order))
            .collect();
        tokio::time::sleep(Duration::from_millis(20)).await;
        let err = pool
            .acquire_for(Arc::from("d"), Duration::from_secs(1))
            .await
            .expect_err("full, every queue has one");
        assert_eq!(err.status().as_u16(), 503);
        drop(held);
        for t in w {
            assert!(t.await.expect("join"));
        }
    }

    #[test]
    fn thread_cpu_time_advances_with_work_not_with_sleep() {
        let t0 = thread_cpu();
        std::thread::sleep(Duration::from_millis(30));
        let slept = thread_cpu().saturating_sub(t0);
        let t1 = thread_cpu();
        let start = Instant::now();
        let mut x = 0u64;
        // Busy until the clock shows 20 ms of CPU (on a loaded machine that takes longer).
        while thread_cpu().saturating_sub(t1) < Duration::from_millis(20)
            && start.elapsed() < Duration::from_secs(10)
        {
            for _ in 0..10_000 {
                x = x.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            }
        }
        std::hint::black_box(x);
        let worked = thread_cpu().saturating_sub(t1);
        assert!(slept < Duration::from_millis(5), "sleep counted {slept:?}");
        assert!(
            worked >= Duration::from_millis(20),
            "work counted {worked:?}"
        );
    }
}
