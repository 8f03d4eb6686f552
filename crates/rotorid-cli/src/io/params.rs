//! The six identified parameters of the paper's eq. (1), per direction: m_x, c_x, k_x
//! (x direction) and m_z, c_z, k_z (z direction); m is one physical mass but is identified
//! independently in each direction. Units: m [kg], c [N s/m], k [N/m].

use serde::{Deserialize, Serialize};

/// One value of type `T` per identified parameter (serialised with these field names).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct ParameterSet<T> {
    /// Mass from the x equation [kg].
    pub m_x: T,
    /// Damping in x [N s/m].
    pub c_x: T,
    /// Stiffness in x [N/m].
    pub k_x: T,
    /// Mass from the z equation [kg].
    pub m_z: T,
    /// Damping in z [N s/m].
    pub c_z: T,
    /// Stiffness in z [N/m].
    pub k_z: T,
}

impl<T> ParameterSet<T> {
    /// From values in the order of the estimates CSV (m_x, c_x, k_x, m_z, c_z, k_z).
    pub fn from_array([m_x, c_x, k_x, m_z, c_z, k_z]: [T; 6]) -> Self {
        Self {
            m_x,
            c_x,
            k_x,
            m_z,
            c_z,
            k_z,
        }
    }
}

impl<T: Copy> ParameterSet<T> {
    /// The values in the order of the estimates CSV (m_x, c_x, k_x, m_z, c_z, k_z).
    pub fn to_array(self) -> [T; 6] {
        [self.m_x, self.c_x, self.k_x, self.m_z, self.c_z, self.k_z]
    }
}
