//! Messages every component answers (`<ns>/<component>/info`).
//!
//! The host lists its plugins on `<ns>/host/plugins`; a component (vision,
//! controller, …) is a process of its own, so it answers for itself. A client finds
//! what is on the bus by querying `<ns>/*/info` ([`crate::keys::KeySpace::component_info_all`]).

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Reply of `<ns>/<component>/info`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ComponentInfo {
    /// The component's name, which is also its key prefix (`vision`, `controller`).
    pub name: String,
    /// The component's version.
    pub version: String,
    /// One-line description.
    pub description: String,
    /// The bus namespace the component serves.
    pub namespace: String,
    /// The keys it answers (queryables) and publishes, full key expressions.
    #[serde(default)]
    pub keys: Vec<String>,
}
