//! The SLAM filter: one call of [`SlamFilter::step`] per epoch runs the
//! prediction (1), the association (3)-(7), the particle belief update of
//! the UE (Sec. IV-D), the source updates and the map maintenance (Sec.
//! III-D). See the crate docs for how this maps onto the paper.

use std::sync::Arc;

use faer::Mat;
use mmtrack_core::random::standard_normal;
use mmtrack_core::slam::{PathMeasurement, SlamEpoch, SourceType, UeState};
use mmtrack_core::wrap_angle_rad;
use rand::RngExt;

use crate::association::associate;
use crate::config::SlamConfig;
use crate::error::SlamError;
use crate::map::{Gauss3, Hypotheses, MapSource, SourceStatus, fuse};
use crate::model::{FastPath, UE_MEAS_DIM, invert, jacobians};
use crate::particles::{Moments, NextStage, Particles, PreparedPath, STATE_DIM};
use crate::small::{cholesky_lower, col, from3, mul, sandwich, spd_inverse, symmetrise, to3, to5};
use crate::team::{Team, with_team};

/// The UE estimate of an epoch: the posterior mean and spreads.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UeEstimate {
    /// Posterior mean (speed and turn rate: the 1-step smoothed values).
    pub state: UeState,
    /// Root of the trace of the horizontal position covariance, metres.
    pub position_std_m: f64,
    /// Horizontal position covariance `[xx, xy, yy]`, m^2 (for the
    /// normalised estimation error squared of a consistency check).
    pub position_cov_m2: [f64; 3],
    /// Heading standard deviation, radians.
    pub heading_std_rad: f64,
    /// Clock-bias standard deviation, metres.
    pub clock_bias_std_m: f64,
}

/// What a path was associated with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Decision {
    /// An existing map source.
    Source(u64),
    /// A new (unconfirmed) source created for it.
    NewSource(u64),
    /// Used to initialise the UE from the line of sight (first epoch).
    Initialisation,
    /// Dropped: the UE is not initialised yet (no line of sight so far).
    Waiting,
}

/// One association decision.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathAssociation {
    /// Index of the path in the epoch.
    pub path: usize,
    /// Its source.
    pub decision: Decision,
    /// `log S` of the chosen column (`log P_N` for a new source).
    pub log_score: f64,
}

/// What one epoch did.
#[derive(Debug, Clone, PartialEq)]
pub struct EpochReport {
    /// Epoch index (0-based).
    pub epoch: usize,
    /// Epoch time, nanoseconds.
    pub t_ns: i64,
    /// Whether the UE has been initialised (a line of sight was seen).
    pub initialised: bool,
    /// The UE estimate after the update.
    pub estimate: UeEstimate,
    /// Paths skipped as unusable (NaN, elevation out of range).
    pub skipped_paths: usize,
    /// The association of each usable path.
    pub associations: Vec<PathAssociation>,
    /// Paths from the BS and confirmed sources used in the UE update.
    pub paths_in_update: usize,
    /// Tempering stages run.
    pub stages: usize,
    /// Effective sample size after the update.
    pub ess: f64,
    /// Sources confirmed in this epoch.
    pub confirmed: Vec<u64>,
}

/// The 5G mmWave SLAM filter of Kim et al. 2018.
#[derive(Debug, Clone)]
pub struct SlamFilter {
    config: SlamConfig,
    seed: u64,
    particles: Particles,
    sources: Vec<MapSource>,
    next_id: u64,
    epoch: usize,
    last_t_ns: Option<i64>,
    initialised: bool,
    prior_mean: UeState,
    sigma_var: [f64; 5],
    parallel_phases: u64,
}

/// About how many particles (every `n / 256`-th) a path's VA and SP
/// hypotheses are inverted for ([`SourceModel::hypotheses_of`]).
const HYPOTHESIS_PARTICLES: usize = 256;

/// A predicted path of one source hypothesis: `(weight, eta, S^-1, ln det S)`.
type Hypothesis = (f64, [f64; 5], [[f64; 5]; 5], f64);

/// The information `W` of a path's message to the UE (`5 x 5`).
type Information = [[f64; 5]; 5];

/// What [`SlamFilter::associate`] returns: `(column, log S)` per path, and
/// per source the information of its message to the UE at the prior mean.
type Association = (Vec<(Option<usize>, f64)>, Vec<Option<Information>>);

/// The UE state of a particle-state vector.
fn ue_of(s: &[f64; STATE_DIM], z_m: f64) -> UeState {
    UeState {
        position_m: [s[0], s[1], z_m],
        heading_rad: s[2],
        speed_mps: s[3],
        turn_rate_radps: s[4],
        clock_bias_m: s[5],
    }
}

/// The `4 x 4` covariance of `[x, y, heading, bias]` from the `6 x 6` one.
fn meas_cov(cov: &Mat<f64>) -> Mat<f64> {
    const IDX: [usize; UE_MEAS_DIM] = [0, 1, 2, 5];
    Mat::from_fn(UE_MEAS_DIM, UE_MEAS_DIM, |i, j| cov[(IDX[i], IDX[j])])
}

/// `z - eta` with wrapped angles.
fn innovation(z: &[f64; 5], eta: &[f64; 5]) -> [f64; 5] {
    [z[0] - eta[0], wrap_angle_rad(z[1] - eta[1]), z[2] - eta[2], wrap_angle_rad(z[3] - eta[3]), z[4] - eta[4]]
}

impl SlamFilter {
    /// A filter with the prior of Sec. V-A centred on `prior_mean`, the map
    /// holding only the BS.
    ///
    /// # Errors
    /// [`SlamError::InvalidConfig`] for a bad configuration or prior.
    pub fn new(config: SlamConfig, prior_mean: UeState, seed: u64) -> Result<Self, SlamError> {
        config.validate()?;
        let p = prior_mean;
        for (field, v) in [
            ("prior_mean.x_m", p.position_m[0]),
            ("prior_mean.y_m", p.position_m[1]),
            ("prior_mean.z_m", p.position_m[2]),
            ("prior_mean.heading_rad", p.heading_rad),
            ("prior_mean.speed_mps", p.speed_mps),
            ("prior_mean.turn_rate_radps", p.turn_rate_radps),
            ("prior_mean.clock_bias_m", p.clock_bias_m),
        ] {
            if !v.is_finite() {
                return Err(crate::error::invalid(field, v, "a finite number"));
            }
        }
        let c = config.clone();
        let pos_std = c.prior_position_std_m / std::f64::consts::SQRT_2;
        let chunks = c.particles.div_ceil(c.chunk_size);
        let particles = with_team(chunks, |team| {
            Particles::draw(team, c.particles, c.chunk_size, p.position_m[2], seed, 0x7072_696f, move |rng| {
                let s = [
                    p.position_m[0] + pos_std * standard_normal(rng),
                    p.position_m[1] + pos_std * standard_normal(rng),
                    p.heading_rad + c.prior_heading_std_rad * standard_normal(rng),
                    p.speed_mps + c.prior_speed_std_mps * standard_normal(rng),
                    p.turn_rate_radps + c.prior_turn_rate_std_radps * standard_normal(rng),
                    p.clock_bias_m + c.prior_clock_bias_std_m * standard_normal(rng),
                ];
                (s, 0.0)
            })
        });
        let bs = MapSource {
            id: 0,
            status: SourceStatus::BaseStation,
            belief: Gauss3::isotropic(config.bs_m, 0.0),
            first_seen_epoch: 0,
            last_seen_epoch: 0,
            sightings: 0,
            confirmed_epoch: Some(0),
            hypotheses: None,
        };
        let a2 = config.angle_std_rad * config.angle_std_rad;
        let sigma_var = [config.toa_std_m * config.toa_std_m, a2, a2, a2, a2];
        Ok(Self {
            config,
            seed,
            particles,
            sources: vec![bs],
            next_id: 1,
            epoch: 0,
            last_t_ns: None,
            initialised: false,
            prior_mean,
            sigma_var,
            parallel_phases: 0,
        })
    }

    /// The map: the BS first, then the other sources in order of creation.
    #[must_use]
    pub fn sources(&self) -> &[MapSource] {
        &self.sources
    }

    /// The configuration.
    #[must_use]
    pub fn config(&self) -> &SlamConfig {
        &self.config
    }

    /// Parallel phases run so far (phases of more than one task: each is a
    /// synchronisation point of the threads when there are more than one;
    /// the same count for any thread count).
    #[must_use]
    pub fn parallel_phases(&self) -> u64 {
        self.parallel_phases
    }

    /// Runs one epoch.
    ///
    /// Unusable paths (a NaN, an elevation outside `[-pi/2, pi/2]`) are
    /// skipped and counted, or refused when `config.strict`; an empty epoch
    /// only predicts.
    ///
    /// # Errors
    /// [`SlamError::TimeNotIncreasing`], [`SlamError::BadPath`] (strict
    /// mode), [`SlamError::WeightsDegenerate`], [`SlamError::Association`].
    pub fn step(&mut self, epoch: &SlamEpoch) -> Result<EpochReport, SlamError> {
        with_team(self.particles.chunk_count(), |team| {
            let report = self.step_on(team, epoch);
            self.parallel_phases += team.phases();
            report
        })
    }

    /// [`SlamFilter::step`] in one parallel region: `team` runs its
    /// per-particle phases.
    fn step_on(&mut self, team: &Team, epoch: &SlamEpoch) -> Result<EpochReport, SlamError> {
        let k = self.epoch;
        if let Some(prev) = self.last_t_ns
            && epoch.t_ns <= prev
        {
            return Err(SlamError::TimeNotIncreasing { epoch: k, t_ns: epoch.t_ns, previous_t_ns: prev });
        }
        let mut paths = Vec::with_capacity(epoch.paths.len());
        let mut path_index = Vec::with_capacity(epoch.paths.len());
        let mut skipped_paths = 0;
        for (i, p) in epoch.paths.iter().enumerate() {
            match p.validate() {
                Ok(()) => {
                    paths.push(*p);
                    path_index.push(i);
                }
                Err(source) if self.config.strict => return Err(SlamError::BadPath { epoch: k, path: i, source }),
                Err(_) => skipped_paths += 1,
            }
        }
        if let Some(prev) = self.last_t_ns {
            let dt_s = (epoch.t_ns - prev) as f64 * 1e-9;
            let c = &self.config;
            self.particles.predict(
                team,
                dt_s,
                [c.speed_std_mps, c.turn_rate_std_radps, c.clock_bias_std_m],
                self.seed,
                k as u64,
            );
        }
        self.last_t_ns = Some(epoch.t_ns);
        self.epoch += 1;

        let prior = self.particles.moments(team);
        let (assignment, information) = self.associate(team, &paths, &prior, k)?;
        let mut associations = Vec::with_capacity(paths.len());
        let mut init_path = None;
        if !self.initialised {
            let los = assignment.iter().position(|a| a.0 == Some(0));
            match los {
                Some(l) => {
                    self.initialise_from_los(team, &paths[l]);
                    self.initialised = true;
                    init_path = Some(l);
                }
                None => {
                    for (l, (_, score)) in assignment.iter().enumerate() {
                        associations.push(PathAssociation {
                            path: path_index[l],
                            decision: Decision::Waiting,
                            log_score: *score,
                        });
                    }
                    let ess = self.particles.ess_with(team, 0.0, &[]);
                    return Ok(self.report(k, epoch.t_ns, skipped_paths, associations, 0, 0, Vec::new(), &prior, ess));
                }
            }
        }

        // UE update with the paths of the BS and of confirmed sources.
        // The particles changed since `prior` only if the LOS initialised them.
        let ue_now = if init_path.is_some() { self.particles.moments(team) } else { prior.clone() };
        let ue_mean = ue_of(&ue_now.mean, self.particles.z_m);
        let mut prepared = Vec::new();
        for (l, (column, _)) in assignment.iter().enumerate() {
            let Some(m) = column else { continue };
            if Some(l) == init_path {
                continue;
            }
            let source = &self.sources[*m];
            let kind = match source.status {
                SourceStatus::BaseStation => SourceType::BaseStation,
                SourceStatus::VirtualAnchor => SourceType::VirtualAnchor,
                SourceStatus::ScatteringPoint => SourceType::ScatteringPoint,
                SourceStatus::Unconfirmed => continue,
            };
            // The association found `W` at the prior mean, which is the UE
            // mean here unless the LOS initialised the particles.
            let p = match (init_path, information[*m]) {
                (None, Some(w)) => Some(PreparedPath {
                    fast: FastPath::new(kind, source.belief.mean_m, self.config.bs_m, &paths[l].to_array()),
                    information: w,
                }),
                _ => self.prepare(&paths[l], kind, &source.belief, &ue_mean),
            };
            prepared.extend(p);
        }
        let paths_in_update = prepared.len();
        let stages = self.update_particles(team, prepared, k)?;
        let post = self.particles.moments(team);
        let sample = self.particles.weighted_sample(team, HYPOTHESIS_PARTICLES);

        // Sources: confirmed ones by an iterated EKF, unconfirmed and new ones
        // by their two hypotheses.
        // Each path touches one source (eq. (7d)), so what it does to it is
        // found for all paths at once on the team, then applied in path order.
        let post_mean = ue_of(&post.mean, self.particles.z_m);
        let pre_cov = meas_cov(&ue_now.cov);
        let asks: Vec<SourceAsk> = assignment
            .iter()
            .enumerate()
            .map(|(l, (column, _))| match column {
                _ if Some(l) == init_path => SourceAsk::Nothing,
                Some(m) => match self.sources[*m].status {
                    SourceStatus::BaseStation => SourceAsk::Nothing,
                    SourceStatus::VirtualAnchor => SourceAsk::Ekf(self.sources[*m].belief, SourceType::VirtualAnchor),
                    SourceStatus::ScatteringPoint => {
                        SourceAsk::Ekf(self.sources[*m].belief, SourceType::ScatteringPoint)
                    }
                    SourceStatus::Unconfirmed => SourceAsk::Hypotheses,
                },
                None => SourceAsk::Hypotheses,
            })
            .collect();
        let model = SourceModel { config: self.config.clone(), sigma_var: self.sigma_var };
        let (z_m, paths_now) = (self.particles.z_m, paths.clone());
        let updates = team.map(asks.len(), move |l| {
            model.update(asks[l], &paths_now[l], (&ue_mean, &pre_cov), &post_mean, (&sample, z_m))
        });
        let mut confirmed = Vec::new();
        for (l, ((column, score), update)) in assignment.iter().zip(updates).enumerate() {
            let decision = if Some(l) == init_path {
                self.sources[0].sightings += 1;
                self.sources[0].last_seen_epoch = k;
                Decision::Initialisation
            } else if let Some(m) = *column {
                self.observe_source(m, update, k, &mut confirmed);
                Decision::Source(self.sources[m].id)
            } else {
                let id = self.create_source(update, k);
                Decision::NewSource(id)
            };
            associations.push(PathAssociation { path: path_index[l], decision, log_score: *score });
        }
        self.maintain(k);
        let ess = self.particles.ess_with(team, 0.0, &[]);
        Ok(self.report(k, epoch.t_ns, skipped_paths, associations, paths_in_update, stages, confirmed, &post, ess))
    }

    #[allow(clippy::too_many_arguments)]
    fn report(
        &self,
        k: usize,
        t_ns: i64,
        skipped_paths: usize,
        associations: Vec<PathAssociation>,
        paths_in_update: usize,
        stages: usize,
        confirmed: Vec<u64>,
        m: &Moments,
        ess: f64,
    ) -> EpochReport {
        let estimate = UeEstimate {
            state: ue_of(&m.mean, self.particles.z_m),
            position_std_m: (m.cov[(0, 0)] + m.cov[(1, 1)]).max(0.0).sqrt(),
            position_cov_m2: [m.cov[(0, 0)], m.cov[(0, 1)], m.cov[(1, 1)]],
            heading_std_rad: m.cov[(2, 2)].max(0.0).sqrt(),
            clock_bias_std_m: m.cov[(5, 5)].max(0.0).sqrt(),
        };
        EpochReport {
            epoch: k,
            t_ns,
            initialised: self.initialised,
            estimate,
            skipped_paths,
            associations,
            paths_in_update,
            stages,
            ess,
            confirmed,
        }
    }

    /// `log S^D_lm` of eq. (3)-(5) for every (path, source) pair, the
    /// unconfirmed sources as the mixture (4) of their two hypotheses, then
    /// the assignment (7). Returns `(column, log S)` per path, and per
    /// source the information `W = (Sigma + H_m P_m H_m^T)^-1` of its
    /// message to the UE ([`SlamFilter::prepare`]) linearised at the prior
    /// mean (confirmed sources and the BS; `None` for the others). Each
    /// source's predicted paths (a linearisation and a `5 x 5` inverse per
    /// hypothesis, and `W` from the same linearisation) are one task on
    /// `team`.
    fn associate(
        &self,
        team: &Team,
        paths: &[PathMeasurement],
        prior: &Moments,
        k: usize,
    ) -> Result<Association, SlamError> {
        let ue = ue_of(&prior.mean, self.particles.z_m);
        let p_s = meas_cov(&prior.cov);
        let log_pd = (self.config.detection_probability / (1.0 - self.config.detection_probability)).ln();
        // Per source: its hypotheses as (weight, eta, S^-1, ln det S).
        let asked: Vec<Vec<(f64, SourceType, Gauss3)>> = self
            .sources
            .iter()
            .map(|source| match source.status {
                SourceStatus::BaseStation => vec![(1.0, SourceType::BaseStation, source.belief)],
                SourceStatus::VirtualAnchor => vec![(1.0, SourceType::VirtualAnchor, source.belief)],
                SourceStatus::ScatteringPoint => vec![(1.0, SourceType::ScatteringPoint, source.belief)],
                SourceStatus::Unconfirmed => source.hypotheses.as_ref().map_or_else(Vec::new, |h| {
                    let mut hyps = vec![(0.5, SourceType::VirtualAnchor, h.va_last)];
                    hyps.extend(h.sp_last.map(|sp| (0.5, SourceType::ScatteringPoint, sp)));
                    hyps
                }),
            })
            .collect();
        let (bs_m, sigma_var) = (self.config.bs_m, self.sigma_var);
        let confirmed: Vec<bool> = self.sources.iter().map(|s| s.status != SourceStatus::Unconfirmed).collect();
        let per_source: Vec<(Vec<Hypothesis>, Option<Information>)> = team.map(asked.len(), move |m| {
            let mut information = None;
            let mut predict = |(w, kind, g): &(f64, SourceType, Gauss3)| {
                let (eta, h_ue, h_src) = jacobians(&ue, bs_m, *kind, g.mean_m)?;
                let from_source = sandwich(&h_src, &from3(&g.cov_m2));
                if confirmed[m] {
                    let mut s = from_source.clone();
                    for i in 0..5 {
                        s[(i, i)] += sigma_var[i];
                    }
                    information = spd_inverse(&s).map(|(inv, _)| to5(&inv));
                }
                let mut s = sandwich(&h_ue, &p_s) + from_source;
                for i in 0..5 {
                    s[(i, i)] += sigma_var[i];
                }
                let (inv, log_det) = spd_inverse(&s)?;
                Some((*w, eta, to5(&inv), log_det))
            };
            let hypotheses = asked[m].iter().filter_map(&mut predict).collect();
            (hypotheses, information)
        });
        let (predicted, information): (Vec<Vec<Hypothesis>>, Vec<_>) = per_source.into_iter().unzip();
        let norm = 2.5 * std::f64::consts::TAU.ln();
        // Before the UE is initialised only the BS is in the map, and a wrong
        // LOS cannot be undone: the LOS must be the shortest path (triangle
        // inequality: a reflected or scattered path is longer) and pass the
        // tighter initialisation gate.
        let gate = if self.initialised { self.config.association_gate } else { self.config.initialisation_gate };
        let shortest = paths.iter().enumerate().min_by(|a, b| a.1.toa_m.total_cmp(&b.1.toa_m)).map(|(l, _)| l);
        let log_s: Vec<Vec<f64>> = paths
            .iter()
            .enumerate()
            .map(|(l, z)| {
                if !self.initialised && Some(l) != shortest {
                    return vec![f64::NEG_INFINITY; predicted.len()];
                }
                let z = z.to_array();
                predicted
                    .iter()
                    .map(|hyps| {
                        let mut terms = [f64::NEG_INFINITY; 2];
                        for (t, (w, eta, inv, log_det)) in hyps.iter().enumerate().take(2) {
                            let r = innovation(&z, eta);
                            let d2: f64 = (0..5).map(|a| (0..5).map(|b| r[a] * inv[a][b] * r[b]).sum::<f64>()).sum();
                            if d2 <= gate {
                                terms[t] = w.ln() - 0.5 * d2 - 0.5 * log_det - norm;
                            }
                        }
                        let max = terms[0].max(terms[1]);
                        if max == f64::NEG_INFINITY {
                            return f64::NEG_INFINITY;
                        }
                        log_pd + max + terms.iter().map(|t| (t - max).exp()).sum::<f64>().ln()
                    })
                    .collect()
            })
            .collect();
        let columns = self.sources.len();
        let log_new = self.config.new_source_density.ln();
        let a = associate(&log_s, columns, log_new).map_err(|source| SlamError::Association { epoch: k, source })?;
        let assignment = a.iter().enumerate().map(|(l, m)| (*m, m.map_or(log_new, |m| log_s[l][m]))).collect();
        Ok((assignment, information))
    }

    /// Step 1 at the first epoch (Sec. IV-D): particles drawn from the LOS
    /// message (DOD azimuth and elevation give the position at the known
    /// height, the DOA azimuth the heading, the TOA the clock bias), each
    /// with its perturbed measurement, weighted by the prior.
    fn initialise_from_los(&mut self, team: &Team, z: &PathMeasurement) {
        let c = self.config.clone();
        let p = self.prior_mean;
        let bs = c.bs_m;
        let z_m = self.particles.z_m;
        let z = *z;
        let var = [
            0.5 * c.prior_position_std_m * c.prior_position_std_m,
            0.5 * c.prior_position_std_m * c.prior_position_std_m,
            c.prior_heading_std_rad * c.prior_heading_std_rad,
            c.prior_clock_bias_std_m * c.prior_clock_bias_std_m,
        ];
        let seed = self.seed;
        let prior_draw = self.particles.states();
        self.particles = Particles::draw(team, c.particles, c.chunk_size, z_m, seed, 0x696e_6974, move |rng| {
            let a = c.angle_std_rad;
            for _ in 0..16 {
                let dod_az = z.dod_az_rad + a * standard_normal(rng);
                let dod_el = z.dod_el_rad + a * standard_normal(rng);
                let t = dod_el.tan();
                let rho = (z_m - bs[2]) / t;
                if !(rho.is_finite() && rho > 0.0 && rho < 1e5) {
                    continue;
                }
                let x = bs[0] + rho * dod_az.cos();
                let y = bs[1] + rho * dod_az.sin();
                let heading = wrap_angle_rad((bs[1] - y).atan2(bs[0] - x) - (z.doa_az_rad + a * standard_normal(rng)));
                let range = ((bs[0] - x).powi(2) + (bs[1] - y).powi(2) + (bs[2] - z_m).powi(2)).sqrt();
                let bias = z.toa_m + c.toa_std_m * standard_normal(rng) - range;
                let speed = p.speed_mps + c.prior_speed_std_mps * standard_normal(rng);
                let turn = p.turn_rate_radps + c.prior_turn_rate_std_radps * standard_normal(rng);
                let d = [
                    x - p.position_m[0],
                    y - p.position_m[1],
                    wrap_angle_rad(heading - p.heading_rad),
                    bias - p.clock_bias_m,
                ];
                let logw = -0.5 * (0..4).map(|i| d[i] * d[i] / var[i]).sum::<f64>();
                return ([x, y, heading, speed, turn, bias], logw);
            }
            // The LOS elevation gives no position (UE at the BS height): keep a prior draw.
            let i = rng.random_range(0..prior_draw.len());
            (prior_draw[i], 0.0)
        });
        self.particles.absorb(team, 0.0);
    }

    /// The path's likelihood as a message to the UE: the source belief
    /// integrated out by linearisation, `W = (Sigma + H_m P_m H_m^T)^-1`.
    fn prepare(&self, z: &PathMeasurement, kind: SourceType, belief: &Gauss3, ue: &UeState) -> Option<PreparedPath> {
        let (_, _, h_src) = jacobians(ue, self.config.bs_m, kind, belief.mean_m)?;
        let mut s = sandwich(&h_src, &from3(&belief.cov_m2));
        for i in 0..5 {
            s[(i, i)] += self.sigma_var[i];
        }
        let (inv, _) = spd_inverse(&s)?;
        Some(PreparedPath {
            fast: FastPath::new(kind, belief.mean_m, self.config.bs_m, &z.to_array()),
            information: to5(&inv),
        })
    }

    /// The UE belief update: the product of the path messages applied in up
    /// to `iterations` tempering stages, each taking as much of the
    /// remaining likelihood as keeps the effective sample size at
    /// `ess_fraction`, with a regularised resampling between stages
    /// (progressive correction). Returns the number of stages.
    fn update_particles(&mut self, team: &Team, paths: Vec<PreparedPath>, k: usize) -> Result<usize, SlamError> {
        let n = self.particles.n as f64;
        let target = self.config.ess_fraction * n;
        let h = self.config.jitter_bandwidth;
        let iterations = self.config.iterations;
        let mut remaining = 1.0;
        let mut stages = 0;
        if paths.is_empty() {
            if self.particles.ess_with(team, 0.0, &[]) < target {
                self.regularised_resample(team, h, k, 0, None)?;
            }
            return Ok(0);
        }
        let paths: Arc<[PreparedPath]> = paths.into();
        // The exponents a stage tries first: all that remains, then the
        // bisection's first midpoint. Their maxima come with the likelihood.
        let first = |remaining: f64| vec![remaining, 0.5 * (0.0 + remaining)];
        // The first stage's likelihood; the resampling's pass computes the others'.
        self.particles.log_likelihood(team, &paths, &first(remaining));
        while remaining > 0.0 && stages < iterations {
            stages += 1;
            let delta = if stages == iterations
                || self.particles.ess_with(team, remaining, &[0.5 * (0.0 + remaining)]) >= target
            {
                remaining
            } else {
                let (mut lo, mut hi) = (0.0, remaining);
                for _ in 0..10 {
                    let mid = 0.5 * (lo + hi);
                    // The next step tries one of these: their maxima come with this pass.
                    let next = [0.5 * (mid + hi), 0.5 * (lo + mid)];
                    if self.particles.ess_with(team, mid, &next) >= target { lo = mid } else { hi = mid }
                }
                lo.max(remaining * 1e-3)
            };
            if self.particles.ess_with(team, delta, &[]) == 0.0 {
                return Err(SlamError::WeightsDegenerate { epoch: k });
            }
            self.particles.absorb(team, delta);
            remaining -= delta;
            if remaining <= 1e-12 {
                remaining = 0.0;
            }
            if remaining > 0.0 || self.particles.ess_with(team, 0.0, &[]) < target {
                let next = (remaining > 0.0 && stages < iterations)
                    .then(|| NextStage { paths: paths.clone(), prefetch: first(remaining) });
                self.regularised_resample(team, h, k, stages, next)?;
            }
        }
        Ok(stages)
    }

    fn regularised_resample(
        &mut self,
        team: &Team,
        h: f64,
        k: usize,
        stage: usize,
        next: Option<NextStage>,
    ) -> Result<(), SlamError> {
        let m = self.particles.moments(team);
        let l = cholesky_lower(&m.cov, 1e-12)
            .ok_or(SlamError::NotPositiveDefinite { epoch: k, what: "particle covariance" })?;
        self.particles.resample(team, Some(&l), h, self.seed, [k as u64, stage as u64], next);
        Ok(())
    }

    /// A path from an existing source: the iterated EKF of a confirmed
    /// source (the message from the UE is its posterior, Gaussian), or the
    /// hypotheses of an unconfirmed one and footnote 3's test; `update` is
    /// what [`SourceModel::update`] found for the path.
    fn observe_source(&mut self, m: usize, update: SourceUpdate, k: usize, confirmed: &mut Vec<u64>) {
        match (self.sources[m].status, update) {
            (SourceStatus::VirtualAnchor | SourceStatus::ScatteringPoint, SourceUpdate::Ekf(g)) => {
                if let Some(g) = g {
                    self.sources[m].belief = g;
                }
            }
            (SourceStatus::Unconfirmed, SourceUpdate::Hypotheses(va, sp)) => {
                let c = &self.config;
                let (ratio, min_drift, min_sightings) = (c.confirm_ratio, c.confirm_min_drift, c.confirm_min_sightings);
                let source = &mut self.sources[m];
                let Some(h) = source.hypotheses.as_mut() else { return };
                if let Some(va) = va {
                    h.observe(va, sp);
                }
                source.belief = h.sp_last.unwrap_or(h.va_last);
                if source.sightings + 1 >= min_sightings {
                    let (d_va, d_sp) = h.drifts();
                    let verdict = if d_sp > ratio * d_va && d_sp > min_drift {
                        Some((SourceStatus::VirtualAnchor, h.va_fused.mean(), h.va_last))
                    } else if d_va > ratio * d_sp && d_va > min_drift {
                        Some((SourceStatus::ScatteringPoint, h.sp_fused.mean(), h.sp_last.unwrap_or(h.va_last)))
                    } else {
                        None
                    };
                    if let Some((status, fused, last)) = verdict {
                        source.status = status;
                        source.belief = Gauss3 { mean_m: fused.unwrap_or(last.mean_m), cov_m2: last.cov_m2 };
                        source.confirmed_epoch = Some(k);
                        source.hypotheses = None;
                        confirmed.push(source.id);
                    }
                }
            }
            _ => {}
        }
        let source = &mut self.sources[m];
        source.sightings += 1;
        source.last_seen_epoch = k;
    }

    /// A new source from a path's hypotheses (`update`, from
    /// [`SourceModel::update`]).
    fn create_source(&mut self, update: SourceUpdate, k: usize) -> u64 {
        let id = self.next_id;
        self.next_id += 1;
        let SourceUpdate::Hypotheses(Some(va), sp) = update else { return id };
        let h = Hypotheses::new(va, sp);
        self.sources.push(MapSource {
            id,
            status: SourceStatus::Unconfirmed,
            belief: sp.unwrap_or(va),
            first_seen_epoch: k,
            last_seen_epoch: k,
            sightings: 1,
            confirmed_epoch: None,
            hypotheses: Some(h),
        });
        id
    }

    /// Sec. III-D: merge confirmed sources of one type closer than
    /// `merge_distance_m`, drop unconfirmed ones that duplicate a confirmed
    /// source, forget unconfirmed ones not seen for a while.
    fn maintain(&mut self, k: usize) {
        let d_merge = self.config.merge_distance_m;
        let dist =
            |a: [f64; 3], b: [f64; 3]| ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt();
        let mut i = 1;
        while i < self.sources.len() {
            let mut j = i + 1;
            while j < self.sources.len() {
                let (a, b) = (&self.sources[i], &self.sources[j]);
                let confirmed_pair = a.status == b.status
                    && matches!(a.status, SourceStatus::VirtualAnchor | SourceStatus::ScatteringPoint);
                if confirmed_pair && dist(a.belief.mean_m, b.belief.mean_m) < d_merge {
                    let merged = fuse(&a.belief, &b.belief);
                    let (sightings, last) = (b.sightings, b.last_seen_epoch);
                    let a = &mut self.sources[i];
                    a.belief = merged;
                    a.sightings += sightings;
                    a.last_seen_epoch = a.last_seen_epoch.max(last);
                    self.sources.remove(j);
                } else {
                    j += 1;
                }
            }
            i += 1;
        }
        let confirmed: Vec<(SourceStatus, [f64; 3])> = self
            .sources
            .iter()
            .filter(|s| matches!(s.status, SourceStatus::VirtualAnchor | SourceStatus::ScatteringPoint))
            .map(|s| (s.status, s.belief.mean_m))
            .collect();
        let forget = self.config.forget_unconfirmed_after_epochs;
        self.sources.retain(|s| {
            if s.status != SourceStatus::Unconfirmed {
                return true;
            }
            if s.last_seen_epoch + forget < k {
                return false;
            }
            let Some(h) = &s.hypotheses else { return false };
            let duplicate = s.sightings >= 2
                && confirmed.iter().any(|(status, at)| match status {
                    SourceStatus::VirtualAnchor => dist(h.va_last.mean_m, *at) < d_merge,
                    _ => h.sp_last.is_some_and(|sp| dist(sp.mean_m, *at) < d_merge),
                });
            !duplicate
        });
    }
}

/// What a path asks of its source.
#[derive(Debug, Clone, Copy)]
enum SourceAsk {
    /// Nothing (the BS, or the path that initialised the UE).
    Nothing,
    /// The iterated EKF of a confirmed source from its belief before the epoch.
    Ekf(Gauss3, SourceType),
    /// The VA and SP hypotheses of the path (an unconfirmed or new source).
    Hypotheses,
}

/// What a path does to its source.
#[derive(Debug, Clone, Copy)]
enum SourceUpdate {
    /// Nothing.
    Nothing,
    /// A confirmed source's belief after its EKF (`None`: it failed, the
    /// belief stays).
    Ekf(Option<Gauss3>),
    /// The VA and SP hypotheses of the path.
    Hypotheses(Option<Gauss3>, Option<Gauss3>),
}

/// The source updates' part of the filter: what they need of it, owned, so
/// the paths' updates can run on the epoch's team.
struct SourceModel {
    config: SlamConfig,
    sigma_var: [f64; 5],
}

impl SourceModel {
    /// What `ask` finds for path `z`: the EKF with the predicted UE belief
    /// (`ue_prior`, the covariance of `[x, y, heading, bias]`) as the
    /// message, or the hypotheses under the posterior (`ue`, a sample of
    /// the particles with their weights, and the height).
    fn update(
        &self,
        ask: SourceAsk,
        z: &PathMeasurement,
        (ue_prior, p_prior): (&UeState, &Mat<f64>),
        ue: &UeState,
        particles: (&[([f64; STATE_DIM], f64)], f64),
    ) -> SourceUpdate {
        match ask {
            SourceAsk::Nothing => SourceUpdate::Nothing,
            SourceAsk::Ekf(belief, kind) => SourceUpdate::Ekf(self.ekf_source(&belief, kind, z, ue_prior, p_prior)),
            SourceAsk::Hypotheses => {
                let (va, sp) = self.hypotheses_of(z, ue, particles);
                SourceUpdate::Hypotheses(va, sp)
            }
        }
    }

    /// Iterated EKF update of a source belief with one path, the UE
    /// uncertainty added to the measurement noise, relinearised up to
    /// `iterations` times.
    fn ekf_source(
        &self,
        prior: &Gauss3,
        kind: SourceType,
        z: &PathMeasurement,
        ue: &UeState,
        p_s: &Mat<f64>,
    ) -> Option<Gauss3> {
        let p = from3(&prior.cov_m2);
        let z = z.to_array();
        let mut mu = prior.mean_m;
        let mut last = None;
        for _ in 0..self.config.iterations {
            let (eta, h_ue, h_src) = jacobians(ue, self.config.bs_m, kind, mu)?;
            let mut r_cov = sandwich(&h_ue, p_s);
            for i in 0..5 {
                r_cov[(i, i)] += self.sigma_var[i];
            }
            let s = sandwich(&h_src, &p) + &r_cov;
            let (s_inv, _) = spd_inverse(&s)?;
            let gain = mul(&mul(&p, &h_src.transpose().to_owned()), &s_inv);
            let nu = innovation(&z, &eta);
            let shift = mul(&h_src, &col(&[prior.mean_m[0] - mu[0], prior.mean_m[1] - mu[1], prior.mean_m[2] - mu[2]]));
            let corr = col(&std::array::from_fn::<f64, 5, _>(|i| nu[i] - shift[(i, 0)]));
            let dx = mul(&gain, &corr);
            let next: [f64; 3] = std::array::from_fn(|i| prior.mean_m[i] + dx[(i, 0)]);
            let moved = (0..3).map(|i| (next[i] - mu[i]).powi(2)).sum::<f64>().sqrt();
            mu = next;
            last = Some((gain, h_src, r_cov, h_ue));
            if moved < 1e-4 {
                break;
            }
        }
        let (gain, h, r_cov, h_ue) = last?;
        let ikh = Mat::<f64>::identity(3, 3) - mul(&gain, &h);
        let mut cov = symmetrise(&(sandwich(&ikh, &p) + sandwich(&gain, &r_cov)));
        if self.config.ue_error_floor {
            cov = psd_max(&cov, &self.ue_induced(&h, &h_ue, p_s)?)?;
        }
        Some(Gauss3 { mean_m: mu, cov_m2: to3(&cov) })
    }

    /// The source error one epoch's UE error induces: `A H_s P_s H_s^T A^T`
    /// with `A = (H_m^T Sigma^-1 H_m)^-1 H_m^T Sigma^-1` the least-squares
    /// inverse of the measurement with respect to the source. The UE error
    /// changes slowly from epoch to epoch, so this part of a source's error
    /// does not average out over its sightings as the measurement noise
    /// does; message passing treats the epochs as independent and would
    /// shrink it all the same (see `SlamConfig::ue_error_floor`).
    fn ue_induced(&self, h_src: &Mat<f64>, h_ue: &Mat<f64>, p_s: &Mat<f64>) -> Option<Mat<f64>> {
        let w = Mat::from_fn(5, 5, |i, j| if i == j { 1.0 / self.sigma_var[i] } else { 0.0 });
        let ht_w = mul(&h_src.transpose().to_owned(), &w);
        let (info_inv, _) = spd_inverse(&mul(&ht_w, h_src))?;
        let a = mul(&info_inv, &ht_w);
        Some(symmetrise(&sandwich(&mul(&a, h_ue), p_s)))
    }

    /// The VA and SP hypotheses of a path under the UE posterior (Sec.
    /// IV-A): the inversion of [`invert`] per particle of `sample` (every
    /// `n / HYPOTHESIS_PARTICLES`-th particle,
    /// [`Particles::weighted_sample`]), weighted, plus the measurement noise
    /// mapped through the inversion at the mean.
    ///
    /// [`Particles::weighted_sample`]: crate::particles::Particles::weighted_sample
    fn hypotheses_of(
        &self,
        z: &PathMeasurement,
        ue: &UeState,
        (sample, z_m): (&[([f64; STATE_DIM], f64)], f64),
    ) -> (Option<Gauss3>, Option<Gauss3>) {
        let bs = self.config.bs_m;
        let mut acc = [Acc::default(), Acc::default()];
        for (s, w) in sample {
            let (va, sp) = invert([s[0], s[1], z_m], s[2], s[5], bs, z);
            acc[0].add(*w, va);
            if let Some(sp) = sp {
                acc[1].add(*w, sp);
            }
        }
        // Measurement noise through the inversion (TOA, DOA az, DOA el).
        let noise = |which: usize| -> Option<Mat<f64>> {
            let at = |dz: [f64; 3]| {
                let zz = PathMeasurement {
                    toa_m: z.toa_m + dz[0],
                    doa_az_rad: z.doa_az_rad + dz[1],
                    doa_el_rad: z.doa_el_rad + dz[2],
                    ..*z
                };
                let (va, sp) = invert(ue.position_m, ue.heading_rad, ue.clock_bias_m, bs, &zz);
                if which == 0 { Some(va) } else { sp }
            };
            let mut j = Mat::zeros(3, 3);
            for c in 0..3 {
                let step = if c == 0 { 1e-3 } else { 1e-5 };
                let mut dz = [0.0; 3];
                dz[c] = step;
                let plus = at(dz)?;
                dz[c] = -step;
                let minus = at(dz)?;
                for r in 0..3 {
                    j[(r, c)] = (plus[r] - minus[r]) / (2.0 * step);
                }
            }
            let sz = Mat::from_fn(3, 3, |i, jj| if i == jj { self.sigma_var[i] } else { 0.0 });
            Some(sandwich(&j, &sz))
        };
        let finish = |a: &Acc, which: usize| -> Option<Gauss3> {
            let g = a.gauss()?;
            let extra = noise(which)?;
            Some(Gauss3 {
                mean_m: g.mean_m,
                cov_m2: std::array::from_fn(|i| {
                    std::array::from_fn(|j| g.cov_m2[i][j] + extra[(i, j)] + if i == j { 1e-6 } else { 0.0 })
                }),
            })
        };
        (finish(&acc[0], 0), finish(&acc[1], 1))
    }
}

/// Weighted first and second moments of 3-D points.
#[derive(Debug, Default)]
struct Acc {
    w: f64,
    s: [f64; 3],
    ss: [[f64; 3]; 3],
}

impl Acc {
    fn add(&mut self, w: f64, p: [f64; 3]) {
        if w.is_nan() || w <= 0.0 || p.iter().any(|v| !v.is_finite()) {
            return;
        }
        self.w += w;
        for i in 0..3 {
            self.s[i] += w * p[i];
            for j in 0..3 {
                self.ss[i][j] += w * p[i] * p[j];
            }
        }
    }

    fn gauss(&self) -> Option<Gauss3> {
        if self.w.is_nan() || self.w <= 0.0 {
            return None;
        }
        let mean: [f64; 3] = std::array::from_fn(|i| self.s[i] / self.w);
        Some(Gauss3 {
            mean_m: mean,
            cov_m2: std::array::from_fn(|i| {
                std::array::from_fn(|j| {
                    (self.ss[i][j] / self.w - mean[i] * mean[j]).max(if i == j { 0.0 } else { f64::MIN })
                })
            }),
        })
    }
}

/// The smallest covariance (in the PSD order, along the eigenvectors of
/// the difference) at least as large as both `a` and `b`:
/// `a + (b - a)_+`.
fn psd_max(a: &Mat<f64>, b: &Mat<f64>) -> Option<Mat<f64>> {
    let d = symmetrise(&(b - a));
    let eig = d.self_adjoint_eigen(faer::Side::Lower).ok()?;
    let (u, lambda) = (eig.U(), eig.S().column_vector());
    let n = a.nrows();
    let plus = Mat::from_fn(n, n, |i, j| (0..n).map(|k| u[(i, k)] * lambda[k].max(0.0) * u[(j, k)]).sum::<f64>());
    Some(symmetrise(&(a + &plus)))
}
