//! Units of REXS attributes (the unit names of the REXS database, e.g. "mm", "1 / min",
//! "N / mm^2") and their conversion into the units of our gear file's fields.
//!
//! A conversion goes straight to the field's unit, so a value given in that unit passes
//! through unchanged (factor 1, no round-off).

/// What an attribute measures, named by the unit of the gear-file field it feeds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// Length, to mm.
    Length,
    /// Angle, to degrees.
    Angle,
    /// Rotational speed, to rpm.
    Speed,
    /// Torque, to N m.
    Torque,
    /// Kinematic viscosity, to mm^2/s.
    KinematicViscosity,
    /// Temperature, to degrees Celsius.
    Temperature,
    /// Density, to kg/m^3.
    Density,
    /// Stress or modulus, to MPa.
    Stress,
    /// Hardness (Vickers or Brinell number), to GPa.
    Hardness,
    /// Pressure-viscosity coefficient, to 1/GPa.
    PressureViscosity,
    /// Thermal conductivity, to W/(m K).
    Conductivity,
    /// Dimensionless.
    Ratio,
    /// A share of a whole (a load case's load_duration_fraction), to a fraction of 1.
    Share,
    /// A duration, to hours.
    Duration,
}

impl Quantity {
    /// The unit of the converted value.
    pub fn unit(self) -> &'static str {
        match self {
            Quantity::Length => "mm",
            Quantity::Angle => "deg",
            Quantity::Speed => "rpm",
            Quantity::Torque => "N m",
            Quantity::KinematicViscosity => "mm^2/s",
            Quantity::Temperature => "degC",
            Quantity::Density => "kg/m^3",
            Quantity::Stress => "MPa",
            Quantity::Hardness => "GPa",
            Quantity::PressureViscosity => "1/GPa",
            Quantity::Conductivity => "W/(m K)",
            Quantity::Ratio => "-",
            Quantity::Share => "(fraction of 1)",
            Quantity::Duration => "h",
        }
    }

    /// The REXS units this quantity accepts.
    pub fn accepted(self) -> &'static [&'static str] {
        match self {
            Quantity::Length => &["mm", "m", "mum", "cm"],
            Quantity::Angle => &["deg", "°", "rad"],
            Quantity::Speed => &["1 / min", "1 / s", "rad / s"],
            Quantity::Torque => &["N m", "N mm", "kN m"],
            Quantity::KinematicViscosity => &["mm^2 / s", "m^2 / s"],
            Quantity::Temperature => &["C", "K"],
            Quantity::Density => &["kg / dm^3", "kg / m^3", "g / cm^3"],
            Quantity::Stress => &["N / mm^2", "MPa", "GPa", "Pa", "N / m^2"],
            Quantity::Hardness => &["HV", "HB"],
            Quantity::PressureViscosity => &["mm^2 / N", "m^2 / N", "1 / GPa"],
            Quantity::Conductivity => &["W / (m K)"],
            Quantity::Ratio => &["none", ""],
            Quantity::Share => &["%", "none", ""],
            Quantity::Duration => &["h", "min", "s"],
        }
    }
}

/// Converts `value` given in the REXS unit `unit` into the unit of `quantity`; None for a unit
/// the quantity does not accept.
///
/// Hardness numbers (Vickers, Brinell) are loads per area in kgf/mm^2: x 9.80665e-3 gives GPa.
pub fn convert(value: f64, unit: &str, quantity: Quantity) -> Option<f64> {
    let unit = normalise(unit);
    let factor = match (quantity, unit.as_str()) {
        (Quantity::Length, "mm") => 1.0,
        (Quantity::Length, "m") => 1000.0,
        (Quantity::Length, "mum") => 1e-3,
        (Quantity::Length, "cm") => 10.0,
        (Quantity::Angle, "deg" | "°") => 1.0,
        (Quantity::Angle, "rad") => 180.0 / std::f64::consts::PI,
        (Quantity::Speed, "1 / min") => 1.0,
        (Quantity::Speed, "1 / s") => 60.0,
        (Quantity::Speed, "rad / s") => 60.0 / (2.0 * std::f64::consts::PI),
        (Quantity::Torque, "N m") => 1.0,
        (Quantity::Torque, "N mm") => 1e-3,
        (Quantity::Torque, "kN m") => 1e3,
        (Quantity::KinematicViscosity, "mm^2 / s") => 1.0,
        (Quantity::KinematicViscosity, "m^2 / s") => 1e6,
        (Quantity::Temperature, "C") => return Some(value),
        (Quantity::Temperature, "K") => return Some(value - 273.15),
        (Quantity::Density, "kg / dm^3" | "g / cm^3") => 1000.0,
        (Quantity::Density, "kg / m^3") => 1.0,
        (Quantity::Stress, "N / mm^2" | "MPa") => 1.0,
        (Quantity::Stress, "GPa") => 1e3,
        (Quantity::Stress, "Pa" | "N / m^2") => 1e-6,
        (Quantity::Hardness, "HV" | "HB") => 9.80665e-3,
        (Quantity::PressureViscosity, "mm^2 / N") => 1e3,
        (Quantity::PressureViscosity, "m^2 / N") => 1e9,
        (Quantity::PressureViscosity, "1 / GPa") => 1.0,
        (Quantity::Conductivity, "W / (m K)") => 1.0,
        (Quantity::Ratio, "none" | "") => 1.0,
        (Quantity::Share, "%") => 0.01,
        (Quantity::Share, "none" | "") => 1.0,
        (Quantity::Duration, "h") => 1.0,
        (Quantity::Duration, "min") => 1.0 / 60.0,
        (Quantity::Duration, "s") => 1.0 / 3600.0,
        _ => return None,
    };
    Some(value * factor)
}

/// Unit names as the database writes them: single spaces around "/" (some writers omit them).
fn normalise(unit: &str) -> String {
    let u = unit.trim();
    if u.contains('/') && !u.contains(" / ") {
        u.replace('/', " / ")
    } else {
        u.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn field_units_pass_through_and_others_convert() {
        assert_eq!(convert(36.0, "mm", Quantity::Length), Some(36.0));
        assert_eq!(convert(0.036, "m", Quantity::Length), Some(36.0));
        assert_eq!(convert(1000.0, "1/min", Quantity::Speed), Some(1000.0));
        let rpm = convert(2.0 * std::f64::consts::PI, "rad / s", Quantity::Speed).unwrap();
        assert!((rpm - 60.0).abs() < 1e-12);
        assert_eq!(convert(333.15, "K", Quantity::Temperature), Some(60.0));
        assert_eq!(convert(1.02, "kg / dm^3", Quantity::Density), Some(1020.0));
        assert_eq!(convert(300.0, "N m", Quantity::Torque), Some(300.0));
        assert!((convert(100.0, "HV", Quantity::Hardness).unwrap() - 0.980665).abs() < 1e-15);
        assert_eq!(convert(1.0, "furlong", Quantity::Length), None);
        assert_eq!(convert(1.0, "mm", Quantity::Angle), None);
    }
}
