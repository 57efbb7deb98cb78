//! A new gear file (`wormwear init`): every section with its keys, units and defaults, the
//! numbers those of the 1/40 reference gear, in the thread profile asked for.

use super::ProfileType;

/// The commented template; `{PROFILE}`, `{WORM_GRINDING}` and `{HOB_GRINDING}` are filled in.
const TEMPLATE: &str = include_str!("template.toml");

/// The gear file of `wormwear init` for thread profile `profile` (K and C with the grinding
/// wheel tables their threads need).
pub fn gear_template(profile: ProfileType) -> String {
    let letter = match profile {
        ProfileType::A => "A",
        ProfileType::N => "N",
        ProfileType::I => "I",
        ProfileType::K => "K",
        ProfileType::C => "C",
    };
    let grinding = |member: &str| {
        match profile {
        ProfileType::K => format!(
            "\n# The biconical grinding wheel of the K thread.\n[{member}.grinding_wheel]\n\
             radius_mm = 100.0              # R_g at the point that grinds the reference cylinder\n\
             # axis_distance_mm = 126.0     # optional: default r1 + R_g\n\
             # profile_angle_deg = 21.7     # optional: default the thread's normal pressure angle\n"
        ),
        ProfileType::C => format!(
            "\n# The grinding wheel of the C thread, its flank a circular arc.\n\
             [{member}.grinding_wheel]\n\
             radius_mm = 100.0              # R_g at the point that grinds the reference cylinder\n\
             profile_radius_mm = 100.0      # rho_0 of the arc (well above the thread depth)\n\
             # axis_distance_mm = 126.0     # optional: default r1 + R_g\n\
             # profile_angle_deg = 21.7     # optional: default the thread's normal pressure angle\n"
        ),
        _ => String::new(),
    }
    };
    TEMPLATE
        .replace("{PROFILE}", letter)
        .replace("{WORM_GRINDING}", &grinding("worm"))
        .replace("{HOB_GRINDING}", &grinding("hob"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_profile_gives_a_file_that_loads() {
        for profile in ProfileType::ALL {
            let text = gear_template(profile);
            let gear = super::super::load_from_str(&text)
                .unwrap_or_else(|e| panic!("{profile:?}: {e}\n{text}"));
            assert_eq!(gear.worm.profile, profile);
            assert_eq!(gear.hob.profile, profile);
            assert!(!text.contains('{'), "{profile:?}: a placeholder left");
        }
    }

    /// Every optional key the template shows commented out ("# key = value") is one the
    /// input takes: the file with all of them uncommented loads.
    #[test]
    fn every_commented_key_is_accepted() {
        let text = gear_template(ProfileType::A);
        let mut uncommented = 0;
        let lines: Vec<String> = text
            .lines()
            .map(|line| {
                let rest = line.strip_prefix("# ").unwrap_or("");
                let key = rest.split(" = ").next().unwrap_or("");
                let is_key = rest.contains(" = ")
                    && !key.is_empty()
                    && key
                        .chars()
                        .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_');
                if is_key {
                    uncommented += 1;
                    rest.to_string()
                } else {
                    line.to_string()
                }
            })
            .collect();
        assert!(uncommented > 20, "{uncommented} keys");
        let text = lines.join("\n");
        super::super::load_from_str(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
    }
}
