//! The reduced model against the full one (issue 27 item 3): placeholder replaced below.
