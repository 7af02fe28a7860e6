//! The physical grasp every method evaluates: contacts, friction, force limits,
//! torque scale and reference point.
//!
//! A [`Grasp`] is validated once when it is built (at least two contacts,
//! `μ > 0`, positive finite force limits, positive characteristic length), so
//! the force-closure methods can take `&Grasp` and run without re-checking or
//! allocating. Each contact has its own force limit `f_max,i` — the normal
//! force a finger can push with, either one fixed value for every finger or,
//! per contact, the value [`crate::finger_force`] derives from the finger's
//! Jacobian and joint effort limits.
//!
//! ```
//! use nalgebra::{Point3, Vector3};
//! use tsukami_grasp::{contact::Contact, grasp::Grasp};
//!
//! let contacts = vec![
//!     Contact::new(Point3::new(0.03, 0.0, 0.0), -Vector3::x()).unwrap(),
//!     Contact::new(Point3::new(-0.03, 0.0, 0.0), Vector3::x()).unwrap(),
//! ];
//! let grasp = Grasp::new(contacts, 0.5, 10.0, 0.06, Point3::origin()).unwrap();
//! assert_eq!(grasp.torque_scale(), 1.0 / 0.06);
//! ```

use nalgebra::{Point3, Vector3};

use crate::contact::Contact;
use crate::grasp_matrix::{weight_wrench, Wrench};

/// Why a grasp could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GraspError {
    /// Fewer than two contacts: one point contact can never be force closure
    /// and is almost always a caller's mistake.
    #[error("a grasp needs at least 2 contacts, got {0}")]
    TooFewContacts(usize),
    /// The friction coefficient is not a positive finite number.
    #[error("friction coefficient must be positive and finite, got {0}")]
    BadFriction(f64),
    /// A contact's force limit is not a positive finite number.
    #[error("force limit of contact {index} must be positive and finite, got {value}")]
    BadForceLimit {
        /// Index of the contact.
        index: usize,
        /// The rejected value.
        value: f64,
    },
    /// The number of per-contact force limits differs from the number of contacts.
    #[error("{limits} force limits given for {contacts} contacts")]
    LimitCount {
        /// Number of limits given.
        limits: usize,
        /// Number of contacts.
        contacts: usize,
    },
    /// The characteristic length is not a positive finite number.
    #[error("characteristic length must be positive and finite, got {0}")]
    BadLength(f64),
    /// The reference point has a non-finite coordinate.
    #[error("reference point has a non-finite coordinate")]
    BadReference,
}

/// A validated grasp: contacts with friction `μ`, per-contact normal force
/// limits, torque scale `γ = 1 / characteristic_length` and the reference
/// point torques are taken about (normally the centre of mass).
#[derive(Debug, Clone, PartialEq)]
pub struct Grasp {
    contacts: Vec<Contact>,
    force_limits: Vec<f64>,
    mu: f64,
    torque_scale: f64,
    reference: Point3<f64>,
}

impl Grasp {
    /// A grasp with the same force limit `f_max` (N) at every contact.
    pub fn new(
        contacts: Vec<Contact>,
        mu: f64,
        f_max: f64,
        characteristic_length: f64,
        reference: Point3<f64>,
    ) -> Result<Self, GraspError> {
        let limits = vec![f_max; contacts.len()];
        Self::with_force_limits(contacts, limits, mu, characteristic_length, reference)
    }

    /// A grasp with one force limit (N) per contact.
    pub fn with_force_limits(
        contacts: Vec<Contact>,
        force_limits: Vec<f64>,
        mu: f64,
        characteristic_length: f64,
        reference: Point3<f64>,
    ) -> Result<Self, GraspError> {
        if contacts.len() < 2 {
            return Err(GraspError::TooFewContacts(contacts.len()));
        }
        if force_limits.len() != contacts.len() {
            return Err(GraspError::LimitCount {
                limits: force_limits.len(),
                contacts: contacts.len(),
            });
        }
        if !(mu.is_finite() && mu > 0.0) {
            return Err(GraspError::BadFriction(mu));
        }
        if let Some((index, &value)) = force_limits
            .iter()
            .enumerate()
            .find(|(_, f)| !(f.is_finite() && **f > 0.0))
        {
            return Err(GraspError::BadForceLimit { index, value });
        }
        if !(characteristic_length.is_finite() && characteristic_length > 0.0) {
            return Err(GraspError::BadLength(characteristic_length));
        }
        if !reference.coords.iter().all(|x| x.is_finite()) {
            return Err(GraspError::BadReference);
        }
        Ok(Self {
            contacts,
            force_limits,
            mu,
            torque_scale: 1.0 / characteristic_length,
            reference,
        })
    }

    /// The contacts.
    pub fn contacts(&self) -> &[Contact] {
        &self.contacts
    }

    /// Number of contacts `n`.
    pub fn len(&self) -> usize {
        self.contacts.len()
    }

    /// Always false: a grasp has at least two contacts.
    pub fn is_empty(&self) -> bool {
        self.contacts.is_empty()
    }

    /// Per-contact normal force limits `f_max,i` (N).
    pub fn force_limits(&self) -> &[f64] {
        &self.force_limits
    }

    /// Friction coefficient `μ`.
    pub fn mu(&self) -> f64 {
        self.mu
    }

    /// Torque scale `γ` (1/m).
    pub fn torque_scale(&self) -> f64 {
        self.torque_scale
    }

    /// The point torques are taken about.
    pub fn reference(&self) -> &Point3<f64> {
        &self.reference
    }

    /// The wrench of the weight `mass · gravity` at `center_of_mass`, about
    /// this grasp's reference point with its torque scale.
    pub fn weight_wrench(
        &self,
        mass: f64,
        gravity: &Vector3<f64>,
        center_of_mass: &Point3<f64>,
    ) -> Wrench {
        weight_wrench(
            mass,
            gravity,
            center_of_mass,
            &self.reference,
            self.torque_scale,
        )
    }
}
