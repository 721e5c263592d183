/// Quality of a GNSS fix, as NMEA GGA reports it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum GnssFixQuality {
    /// Fix quality not reported by the source.
    Unknown,
    /// No fix.
    NoFix,
    /// Autonomous GNSS fix.
    Autonomous,
    /// Differential (SBAS/DGPS) fix.
    Differential,
    /// RTK with fixed integer ambiguities.
    RtkFixed,
    /// RTK with float ambiguities.
    RtkFloat,
    /// Dead reckoning (INS-only).
    DeadReckoning,
}

impl GnssFixQuality {
    /// Stable integer code used in recordings and tables (documented in `schemas/`).
    #[must_use]
    pub fn code(self) -> u32 {
        match self {
            Self::Unknown => 0,
            Self::NoFix => 1,
            Self::Autonomous => 2,
            Self::Differential => 3,
            Self::RtkFixed => 4,
            Self::RtkFloat => 5,
            Self::DeadReckoning => 6,
        }
    }

    /// Inverse of [`GnssFixQuality::code`]; `None` for an unknown code.
    #[must_use]
    pub fn from_code(code: u32) -> Option<Self> {
        Some(match code {
            0 => Self::Unknown,
            1 => Self::NoFix,
            2 => Self::Autonomous,
            3 => Self::Differential,
            4 => Self::RtkFixed,
            5 => Self::RtkFloat,
            6 => Self::DeadReckoning,
            _ => return None,
        })
    }
}

/// One GNSS position fix (WGS-84).
#[derive(Debug, Clone, PartialEq)]
pub struct GnssFix {
    /// Fix time, nanoseconds since the UNIX epoch.
    pub t_ns: i64,
    /// Geodetic latitude, degrees, north positive.
    pub latitude_deg: f64,
    /// Geodetic longitude, degrees, east positive.
    pub longitude_deg: f64,
    /// Height, metres (above the ellipsoid when known, else above mean sea level;
    /// the recording metadata says which), when the source gives one: `None`
    /// for e.g. an NMEA RMC without a GGA (NaN is not used for "unknown").
    pub altitude_m: Option<f64>,
    /// 1-sigma horizontal position uncertainty, metres, when the source gives one
    /// (NaN is not used for "unknown"; `None` is).
    pub horizontal_sigma_m: Option<f64>,
    /// Number of satellites used, when reported.
    pub num_satellites: Option<u32>,
    /// Fix quality.
    pub quality: GnssFixQuality,
}
