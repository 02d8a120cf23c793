//! The forces a simulated body feels, each a plain function of the model's state and its own
//! parameters: joint torques from PD control ([`pd`]) and the joint model ([`limits`]: friction
//! inside the range, a spring–damper past it), floor contact ([`contact`]: penalty boxes with
//! Coulomb friction) and applied external forces ([`external`]: pushes).

pub mod contact;
pub mod external;
pub mod limits;
pub mod pd;
