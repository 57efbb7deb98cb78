//! The maps of a map state (`[wear] map_cycles`): cumulative wear, wear per cycle, film thickness
//! and ratio, the loaded pattern, the damage, the friction, the run-in roughness, and
//! `wheel_flank_wear.vtp` with them.

use super::*;

/// The maps and node table of one state.
pub(super) struct StateMaps<'a> {
    pub(super) geo: &'a Geometry,
    pub(super) tca: &'a Tca,
    pub(super) view: &'a StepView<'a>,
    pub(super) dir: &'a Path,
}

impl StateMaps<'_> {
    /// The state's record (its last).
    fn record(&self) -> &crate::wear::StepRecord {
        self.view
            .state
            .records
            .last()
            .expect("a state has a record")
    }

    /// Map of a node field of the loaded flank (cell means, times `scale`), coloured over
    /// [0, top] or [0, its maximum], with the active flank and the worm tip's trace.
    pub(super) fn node_map(
        &self,
        path: &Path,
        title: &str,
        field: &FlankField,
        scale: f64,
        bar: &str,
        top: Option<f64>,
    ) -> Result<(), OutputError> {
        let wf = self.geo.wheel_flank(self.tca.loaded_flank);
        let overlays = [
            flank_outline(wf, "active flank", 5),
            tip_trace_series(self.tca),
        ];
        let values: Vec<f64> = field.cell_means().iter().map(|v| v * scale).collect();
        let hi = top.unwrap_or_else(|| {
            values
                .iter()
                .copied()
                .filter(|v| v.is_finite())
                .fold(0.0, f64::max)
        });
        wheel_flank_map(
            path,
            title,
            wf,
            &values,
            (0.0, if hi > 0.0 { hi } else { 1.0 }),
            bar,
            &overlays,
            &[],
        )
    }

    /// The principal shear stress below the most damaged node (MODEL §8.1), from this state's
    /// loaded analysis: `wear_subsurface_section.svg` (None: no node is damaged or loaded).
    pub(super) fn damage_section(&self) -> Result<Option<PathBuf>, OutputError> {
        let (state, wf) = (self.view.state, self.geo.wheel_flank(self.tca.loaded_flank));
        let Some((k, _)) = state
            .damage
            .iter()
            .enumerate()
            .filter(|(_, &d)| d > 0.0)
            .max_by(|a, b| a.1.total_cmp(b.1))
        else {
            return Ok(None);
        };
        let node = wf.nodes[k];
        let path = self.dir.join("wear_subsurface_section.svg");
        let place = format!("at the most damaged node (r = {:.2} mm)", node.r * 1e3);
        let drawn = crate::output::ltca::subsurface_section(
            &path,
            self.view.ltca,
            Some((node.r, node.z)),
            &place,
        )?;
        Ok(drawn.then_some(path))
    }

    /// Writes the maps (cumulative wear, wear per cycle, film ratio and thickness, fatigue
    /// damage, loaded pattern) and the node table, their names ending with `suffix` before
    /// the extension.
    pub(super) fn write(&self, suffix: &str) -> Result<Vec<PathBuf>, OutputError> {
        let mut files = self.wear_and_film_maps(suffix)?;
        files.push(self.damage_map(suffix)?);
        if suffix.is_empty() {
            files.extend(self.damage_section()?);
        }
        files.extend(self.plastic_and_pattern(suffix)?);
        files.extend(self.friction_maps(suffix)?);
        files.extend(self.roughness_map(suffix)?);
        Ok(files)
    }

    /// The composite roughness R_q of the worn flank after its running-in (MODEL §6.1):
    /// `wear_roughness_map` with `suffix` (None without running-in: the lubricant's, uniform).
    fn roughness_map(&self, suffix: &str) -> Result<Option<PathBuf>, OutputError> {
        let Some(field) = &self.view.ltca.roughness else {
            return Ok(None);
        };
        let r = self.record();
        let path = self.dir.join(format!("wear_roughness_map{suffix}.svg"));
        self.node_map(
            &path,
            &format!(
                "Composite roughness R_q at {} cycles (running-in; mean {:.3} um, least {:.3} um; \
                 map: cell means)",
                crate::output::cycles_label(r.cycles),
                r.roughness_mean_m * UM,
                r.roughness_min_m * UM
            ),
            field,
            UM,
            "R_q (um)",
            None,
        )?;
        Ok(Some(path))
    }

    /// The friction of this state's loaded analysis (MODEL §13): `wear_friction_coefficient_map`
    /// and `wear_friction_power_map` with `suffix`.
    fn friction_maps(&self, suffix: &str) -> Result<Vec<PathBuf>, OutputError> {
        let wf = self.geo.wheel_flank(self.tca.loaded_flank);
        let r = self.record();
        let overlays = [
            flank_outline(wf, "active flank", 5),
            tip_trace_series(self.tca),
        ];
        crate::output::friction::friction_maps(
            wf,
            self.view.thermal,
            self.dir,
            ("wear_friction", suffix),
            &format!(" at {} cycles", crate::output::cycles_label(r.cycles)),
            &overlays,
        )
    }

    /// The maps of the cumulative wear, the wear per cycle and the film ratio and thickness.
    fn wear_and_film_maps(&self, suffix: &str) -> Result<Vec<PathBuf>, OutputError> {
        let (view, dir) = (self.view, self.dir);
        let state = view.state;
        let mut files = Vec::new();
        let map = |path: &Path, title: &str, field: &FlankField, scale, bar: &str, top| {
            self.node_map(path, title, field, scale, bar, top)
        };
        let r = state.records.last().expect("a state has a record");
        let path = dir.join(format!("wear_map{suffix}.svg"));
        map(
            &path,
            &format!(
                "Cumulative wear after {} cycles (max {:.2} um, mesh-dependent; map: cell means)",
                crate::output::cycles_label(r.cycles),
                r.max_wear_m * UM
            ),
            &state.removal,
            UM,
            "wear depth (um)",
            None,
        )?;
        files.push(path);
        let path = dir.join(format!("wear_per_cycle_map{suffix}.svg"));
        map(
            &path,
            &format!(
                "Wear per cycle at {} cycles (max {:.3} nm; map: cell means)",
                crate::output::cycles_label(r.cycles),
                r.max_wear_per_cycle_m * 1e9
            ),
            &view.cycle.depth,
            1e9,
            "wear per cycle (nm)",
            None,
        )?;
        files.push(path);
        let lambda = FlankField {
            values: view
                .cycle
                .lambda
                .values
                .iter()
                .map(|v| v.min(4.0))
                .collect(),
            ..view.cycle.lambda.clone()
        };
        let path = dir.join(format!("wear_film_ratio_map{suffix}.svg"));
        map(
            &path,
            &format!(
                "Film ratio lambda at {} cycles (clipped at 4: no wear above)",
                crate::output::cycles_label(r.cycles)
            ),
            &lambda,
            1.0,
            "lambda",
            Some(4.0),
        )?;
        files.push(path);
        let path = dir.join(format!("wear_film_thickness_map{suffix}.svg"));
        map(
            &path,
            &format!(
                "Minimum film thickness h_min at {} cycles (Moes-Venner, thermal factor)",
                crate::output::cycles_label(r.cycles)
            ),
            &view.cycle.film,
            UM,
            "h_min (um)",
            None,
        )?;
        files.push(path);
        Ok(files)
    }

    /// The fatigue damage map (MODEL §8.1).
    fn damage_map(&self, suffix: &str) -> Result<PathBuf, OutputError> {
        let state = self.view.state;
        let r = state.records.last().expect("a state has a record");
        let path = self.dir.join(format!("wear_damage_map{suffix}.svg"));
        self.node_map(
            &path,
            &format!(
                "Fatigue damage at {} cycles (max {:.3}, mesh-dependent; 1: pits; map: cell means)",
                crate::output::cycles_label(r.cycles),
                r.max_damage
            ),
            &FlankField {
                values: state.damage.clone(),
                ..state.removal.clone()
            },
            1.0,
            "damage (Miner, wear-relieved)",
            Some(1.0),
        )?;
        Ok(path)
    }

    /// The plastic set's map, the node table and the loaded pattern.
    fn plastic_and_pattern(&self, suffix: &str) -> Result<Vec<PathBuf>, OutputError> {
        let (tca, view, dir) = (self.tca, self.view, self.dir);
        let state = view.state;
        let wf = self.geo.wheel_flank(tca.loaded_flank);
        let mut files = Vec::new();
        let overlays = [flank_outline(wf, "active flank", 5), tip_trace_series(tca)];
        let r = state.records.last().expect("a state has a record");
        let plastic = view.state.plastic_set_nodes_after(view.ltca);
        let path = dir.join(format!("wear_plastic_set_map{suffix}.svg"));
        self.node_map(
            &path,
            &format!(
                "Plastic set (running-in) at {} cycles (max {:.2} um, mesh-dependent; yielded {:.1} % of the \
                 flank; map: cell means)",
                crate::output::cycles_label(r.cycles),
                r.max_plastic_set_m * UM,
                100.0 * r.yielded_area_fraction
            ),
            &plastic,
            UM,
            "plastic set (um)",
            None,
        )?;
        files.push(path);
        let csv = node_table(wf, state, view.cycle, &plastic, view.ltca);
        let path = dir.join(format!("wear_map{suffix}.csv"));
        csv.write(&path)?;
        files.push(path);
        // Loaded pattern (the maximum pressure over the cycle per flank cell).
        {
            let path = dir.join(format!("wear_pattern{suffix}.svg"));
            crate::output::ltca::pattern_map(
                &path,
                wf,
                view.ltca,
                &format!(
                    "Loaded pattern at {} cycles (P_max {:.0} MPa, S0 {:.2})",
                    crate::output::cycles_label(r.cycles),
                    r.max_pressure_pa * MPA,
                    r.contact_area_fraction
                ),
                &overlays,
            )?;
            files.push(path);
        }
        Ok(files)
    }
}
