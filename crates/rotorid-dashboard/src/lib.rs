//! `rotorid dashboard`: a live web page of a fleet (docs/fleet.md, "Dashboard").
//!
//! The server reads what the fleet's workers write on NATS JetStream ([`follow`]): results
//! and error records (`ROTORID_IDENT`), alerts (`ROTORID_ALERT`), each machine's newest
//! result (`ROTORID_LATEST`), its drift baseline (`ROTORID_DRIFT`) and the windows' samples
//! (`ROTORID_RAW`: the newest orbit and every window's 1X vector, [`raw`]); it keeps per
//! machine a bounded ring of windows ([`state`]) and serves ([`http`]) a fleet page, a page
//! per machine, a JSON API and server-sent events that push every change to the open pages.
//! The pages are plain HTML, CSS and JavaScript embedded in the binary: no build step, no
//! request to any other host.
//!
//! Safe by default: read-only, on a loopback address unless given an access token
//! ([`Config::token`]); every text from the bus is put into the pages as text, never as
//! markup.

pub mod follow;
pub mod http;
pub mod raw;
pub mod state;

use std::future::Future;
use std::net::SocketAddr;
use std::sync::Arc;

pub use state::Settings;

/// How the dashboard runs.
#[derive(Debug, Clone)]
pub struct Config {
    /// The NATS server (`nats://127.0.0.1:4222`).
    pub nats: String,
    /// Where to listen.
    pub listen: SocketAddr,
    /// The access token: required of every request when given, and required to listen on
    /// an address other than loopback ([`check_token`]).
    pub token: Option<String>,
    /// What is kept per machine, and when a machine is stale.
    pub settings: Settings,
    /// Raw windows per machine read back from `ROTORID_RAW` at start for the 1X trend (at
    /// most [`Settings::history`]).
    pub raw_backfill: u64,
}

/// Why the dashboard cannot start.
#[derive(Debug, thiserror::Error)]
pub enum DashboardError {
    /// A non-loopback address without a token.
    #[error(
        "--listen {listen} is not a loopback address: anyone who can reach it would see the \
         fleet, so the dashboard needs --token-file FILE (a file holding an access token) to \
         listen there; or listen on 127.0.0.1 and use an SSH tunnel"
    )]
    NotLoopback {
        /// The address.
        listen: SocketAddr,
    },
    /// A token that is too short or holds characters it may not.
    #[error("access token: {problem}")]
    Token {
        /// What is wrong, with what is allowed.
        problem: String,
    },
    /// A setting out of range.
    #[error("{field} = {value} is out of range: {allowed}")]
    Setting {
        /// The option.
        field: &'static str,
        /// Its value.
        value: String,
        /// What is allowed.
        allowed: &'static str,
    },
    /// The address cannot be listened on.
    #[error("--listen {listen}: {source}")]
    Bind {
        /// The address.
        listen: SocketAddr,
        /// Why.
        source: std::io::Error,
    },
    /// The server failed.
    #[error("serving on {listen}: {source}")]
    Serve {
        /// The address.
        listen: SocketAddr,
        /// Why.
        source: std::io::Error,
    },
}

/// Shortest access token \[characters\].
pub const MIN_TOKEN_LEN: usize = 16;
/// Longest access token \[characters\].
pub const MAX_TOKEN_LEN: usize = 256;

/// Check an access token: [`MIN_TOKEN_LEN`] to [`MAX_TOKEN_LEN`] ASCII letters, digits or
/// `- . _ ~ + / =` (it travels in a header, a URL and a cookie as it is).
pub fn check_token(token: &str) -> Result<(), DashboardError> {
    if token.len() < MIN_TOKEN_LEN || token.len() > MAX_TOKEN_LEN {
        return Err(DashboardError::Token {
            problem: format!(
                "{} characters; it must have {MIN_TOKEN_LEN} to {MAX_TOKEN_LEN} (e.g. `openssl \
                 rand -hex 24`)",
                token.len()
            ),
        });
    }
    if let Some(c) = token
        .chars()
        .find(|c| !(c.is_ascii_alphanumeric() || "-._~+/=".contains(*c)))
    {
        return Err(DashboardError::Token {
            problem: format!(
                "holds {c:?}; it may hold only ASCII letters, digits and - . _ ~ + / ="
            ),
        });
    }
    Ok(())
}

/// A dashboard bound to its address, not yet serving.
pub struct Dashboard {
    listener: tokio::net::TcpListener,
    addr: SocketAddr,
    config: Config,
}

impl Dashboard {
    /// Check `config` and bind its address (nothing is read from NATS yet).
    pub async fn bind(config: Config) -> Result<Self, DashboardError> {
        let s = &config.settings;
        if s.history == 0 || s.history > 1_000_000 {
            return Err(DashboardError::Setting {
                field: "--history",
                value: s.history.to_string(),
                allowed: "1 ..= 1000000 windows",
            });
        }
        if !(s.stale_windows.is_finite() && s.stale_windows > 0.0) {
            return Err(DashboardError::Setting {
                field: "--stale-windows",
                value: s.stale_windows.to_string(),
                allowed: "finite and > 0 (window lengths)",
            });
        }
        if s.max_machines == 0 {
            return Err(DashboardError::Setting {
                field: "--max-machines",
                value: "0".into(),
                allowed: ">= 1",
            });
        }
        match &config.token {
            Some(t) => check_token(t)?,
            None if !config.listen.ip().is_loopback() => {
                return Err(DashboardError::NotLoopback {
                    listen: config.listen,
                })
            }
            None => {}
        }
        let listener = tokio::net::TcpListener::bind(config.listen)
            .await
            .map_err(|source| DashboardError::Bind {
                listen: config.listen,
                source,
            })?;
        let addr = listener
            .local_addr()
            .map_err(|source| DashboardError::Bind {
                listen: config.listen,
                source,
            })?;
        Ok(Self {
            listener,
            addr,
            config,
        })
    }

    /// The address it listens on (the port chosen when `--listen` gave port 0).
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// Read the fleet and serve until `shutdown` resolves.
    pub async fn run(
        self,
        shutdown: impl Future<Output = ()> + Send + 'static,
    ) -> Result<(), DashboardError> {
        let shared = follow::Shared::new(
            state::FleetState::new(self.config.settings),
            &self.config.nats,
        );
        tokio::spawn(follow::start(
            Arc::clone(&shared),
            self.config.nats.clone(),
            self.config.raw_backfill,
        ));
        let app = http::App::new(shared, self.config.token.clone());
        // not a graceful shutdown: the pages' event streams never end by themselves
        tokio::select! {
            r = axum::serve(self.listener, http::router(app)) => {
                r.map_err(|source| DashboardError::Serve { listen: self.addr, source })
            }
            () = shutdown => Ok(()),
        }
    }
}
