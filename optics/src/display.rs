//! What the display does to the light the eye gets (`[display]` in a scene file): an additive
//! display adds the glass's light to the real world's, less what [`Compensation`] takes away;
//! a segmented dimmer ([`dimmer`]) takes away a share of the real world's light behind it;
//! [`registration`] is how far either lands from where the real world is.

pub mod dimmer;
pub mod registration;

/// What the display takes away from the glass's light (`[display] compensation`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Compensation {
    /// Nothing: the glass's whole light is added (the paper's conditions).
    #[default]
    None,
    /// The real floor or background the eye sees through the glass (eq. 6 over the glass).
    Background,
}
