//! The safety table's step of the pipeline (MODEL §9.1): the strength rows at K_A times the
//! torque, the sump temperature of S_T, the root stress and the worm's deflection; and the
//! duty cycle's bins on the unworn gear (MODEL §14) the table reads with a spectrum.

use super::*;
use crate::spectrum::{BinRun, Spectrum};

impl Pipeline<'_> {
    /// The bins of the gear's spectrum on the unworn gear and their figures (MODEL §14), when
    /// the gear has a spectrum and the loaded analysis ran (its analyses are the largest
    /// load's bin).
    pub(crate) fn spectrum(
        &mut self,
        geo: &Geometry,
        (tca, ltca, thermal): (
            Option<&Tca>,
            Option<&Ltca>,
            Option<&crate::friction::Thermal>,
        ),
        bending: &Bending,
    ) -> Result<Option<(Vec<BinRun>, Spectrum)>, RunError> {
        let (Some(tca), Some(ltca), Some(thermal), true) =
            (tca, ltca, thermal, self.gear.has_spectrum())
        else {
            return Ok(None);
        };
        let plan = self.request.life.as_ref().or(self.gear.wear.as_ref());
        let film_load = plan.map_or(crate::input::FilmLoad::LoadedAnalysis, |p| p.film_load);
        let endurance = plan.map_or(crate::input::Endurance::DEFAULT, |p| p.endurance);
        let model = bending.model.as_ref().map(|b| b as &dyn BendingModel);
        let runs =
            crate::spectrum::run_bins(self.gear, geo, (tca, ltca, thermal), model, film_load)
                .map_err(RunError::Spectrum)?;
        let summary = crate::spectrum::summarise(self.gear, geo, &runs, &endurance);
        // The largest load's bin is the loaded analysis above, its warnings said.
        for (k, run) in runs.iter().enumerate() {
            if k + 1 == summary.largest_load_bin {
                continue;
            }
            let said = run.ltca.warnings.iter();
            self.warnings
                .extend(said.map(|w| format!("loaded analysis of duty-cycle bin {}: {w}", k + 1)));
        }
        Ok(Some((runs, summary)))
    }

    /// S_T's sump temperature under a spectrum (MODEL §14): the hottest bin's (each bin's own
    /// heat balance, or one solved for the table as [`Self::sump_temperature`] does); a bin
    /// without a steady temperature decides the row.
    fn hottest_sump(
        &mut self,
        geo: &Geometry,
        bending: &Bending,
        runs: &[BinRun],
    ) -> Option<Result<crate::safety::Sump, crate::safety::SumpError>> {
        let mut hottest: Option<Result<crate::safety::Sump, crate::safety::SumpError>> = None;
        for run in runs {
            let inputs = (geo, &run.tca, bending);
            let sump = self.sump_temperature(&run.gear, inputs, &run.ltca, Some(&run.thermal))?;
            let hotter = match (&hottest, &sump) {
                (None, _) | (Some(Ok(_)), Err(_)) => true,
                (Some(Ok(a)), Ok(b)) => b.thermal.oil_temperature_k > a.thermal.oil_temperature_k,
                (Some(Err(_)), _) => false,
            };
            if hotter {
                hottest = Some(sump);
            }
        }
        hottest
    }

    /// The safety table (MODEL §9.1) beside a loaded analysis: its strength rows from a
    /// loaded analysis at K_A times the torque (the run's own when K_A is 1), the wear and
    /// temperature rows from the run's life and heat balance at the nominal torque.
    pub(crate) fn safety(
        &mut self,
        geo: &Geometry,
        tca: Option<&Tca>,
        bending: &Bending,
        (ltca, thermal, life): (
            Option<&Ltca>,
            Option<&crate::friction::Thermal>,
            Option<&Life>,
        ),
        spectrum: Option<&(Vec<BinRun>, Spectrum)>,
    ) -> Result<Option<crate::safety::SafetyTable>, RunError> {
        let (Some(tca), Some(ltca)) = (tca, ltca) else {
            return Ok(None);
        };
        let gear = self.gear;
        let ka = gear.rating.safety.application_factor;
        let scaled = (ka != 1.0).then(|| crate::safety::scaled_torque(gear, ka));
        let ltca_ka = match &scaled {
            Some(g) => {
                let mut ignored = Vec::new();
                Some(loaded_analysis(
                    g,
                    geo,
                    tca,
                    bending.model.as_ref(),
                    &mut ignored,
                )?)
            }
            None => None,
        };
        let endurance = self
            .request
            .life
            .as_ref()
            .or(gear.wear.as_ref())
            .map_or(crate::input::Endurance::DEFAULT, |p| p.endurance);
        let strength = ltca_ka.as_ref().unwrap_or(ltca);
        let worm_deflection = match bending.model {
            Some(_) => Some(self.worm_deflection(geo, strength)?),
            None => None,
        };
        let root_stress = self.root_stress(geo, tca, strength);
        let sump = match spectrum {
            Some((runs, _)) => self.hottest_sump(geo, bending, runs),
            None => self.sump_temperature(gear, (geo, tca, bending), ltca, thermal),
        };
        let table = crate::safety::safety_table(&crate::safety::SafetyInputsOf {
            gear,
            iso: &crate::rating::rate(scaled.as_ref().unwrap_or(gear)),
            ltca: strength,
            thermal,
            records: life.map(|l| l.end.records.as_slice()),
            endurance,
            worm_deflection,
            root_stress,
            sump,
            spectrum: spectrum.map(|s| &s.1),
        });
        let simulated = life.and_then(|l| l.end.records.last()).map(|r| r.cycles);
        self.warnings
            .extend(crate::safety::warnings(&table, endurance, simulated));
        Ok(Some(table))
    }

    /// The sump temperature of S_T (MODEL §9.1, §13): the run's own heat balance, or, when the
    /// run holds the lubricant's fixed temperature and the table has a temperature limit, the
    /// housing's heat balance at the nominal torque solved for the table alone (its `[housing]`
    /// inputs or their defaults; with the transmitted torque, the loaded analysis again at the
    /// balance's temperature, as a run with the balance does); an error is the row's reason.
    fn sump_temperature(
        &mut self,
        gear: &GearSet,
        (geo, tca, bending): (&Geometry, &Tca, &Bending),
        ltca: &Ltca,
        thermal: Option<&crate::friction::Thermal>,
    ) -> Option<Result<crate::safety::Sump, crate::safety::SumpError>> {
        if let Some(t) = thermal.filter(|t| t.mode == "balance") {
            return Some(Ok(crate::safety::Sump {
                thermal: t.clone(),
                own: true,
            }));
        }
        gear.rating.safety.oil_temperature_limit?;
        let rating = crate::rating::rate(gear);
        let other = rating.loss_churning_w + rating.loss_bearings_w + rating.loss_seals_w;
        let mut balanced = gear.clone();
        balanced.housing.balance = true;
        let analyse = |settings: &LtcaSettings, warm: Option<&crate::ltca::WarmStart>| {
            let model = bending.model.as_ref().map(|b| b as &dyn BendingModel);
            crate::ltca::analyse_worn(&balanced, geo, tca, settings, model, None, warm)
        };
        let settings = LtcaSettings::from_gear(&balanced);
        let inputs = (&balanced, geo, tca);
        let at_oil =
            crate::friction::oil_fixed_point(inputs, other, (settings, ltca.clone()), analyse);
        let ltca = match &at_oil {
            Ok(l) => l,
            Err(_) => ltca,
        };
        let contacts = crate::friction::MeshContacts::new(gear, geo, tca, ltca);
        let result = crate::friction::heat_balance(
            &contacts,
            &gear.lubricant,
            &gear.friction,
            &balanced.housing,
            other,
        )
        .map(|thermal| crate::safety::Sump {
            thermal,
            own: false,
        })
        .map_err(|e| crate::safety::SumpError {
            above_c: match &e {
                crate::friction::FrictionError::NoEquilibrium { limit_c, .. } => Some(*limit_c),
                _ => None,
            },
            message: e.to_string(),
        });
        if let Err(e) = result.as_ref().map_err(|e| &e.above_c) {
            if e.is_none() {
                self.warnings.push(format!(
                    "safety: S_T not computed: {}",
                    result.as_ref().err().map_or("", |e| e.message.as_str())
                ));
            }
        }
        Some(result)
    }

    /// The wheel's root stresses under `ltca` (MODEL §9.1) when the safety table asks for them
    /// (an allowable and a fillet radius given); a failure is the row's reason and a warning.
    fn root_stress(
        &mut self,
        geo: &Geometry,
        tca: &Tca,
        ltca: &Ltca,
    ) -> Option<Result<crate::bending::wheel_root::RootStresses, String>> {
        let inputs = &self.gear.rating.safety;
        let (Some(_), Some(radius)) = (inputs.root_stress_allowable, inputs.root_fillet_radius)
        else {
            return None;
        };
        let level = crate::bending::wheel_root::ROOT_LEVEL;
        let result = crate::bending::wheel_root::root_stress_cached(
            self.gear,
            geo,
            ltca,
            (tca.loaded_flank, level, radius),
            Some(&crate::bending::model::cache_dir()),
        )
        .map(|(stresses, warnings)| {
            self.warnings.extend(warnings);
            stresses
        })
        // The sector's mesh follows the fillet: a failure names the radius it was built with.
        .map_err(|e| {
            format!(
                "{e} (the FE wheel sector with rating.root_fillet_radius_mm = {:.3e} mm; about \
                 0.2 m_x, the hob's rounded tip edge, meshes)",
                radius * 1e3
            )
        });
        match &result {
            Err(e) => self.warnings.push(format!("safety: S_F not computed: {e}")),
            Ok(r) if r.face_ends.stress > r.interior.stress => self.warnings.push(format!(
                "safety: the root stress within a module of a face end ({:.1} MPa) exceeds the \
                 one inside ({:.1} MPa) that S_F uses; near the face ends it depends on the \
                 mesh (the face edges' contact load), so S_F may be optimistic there",
                r.face_ends.stress * 1e-6,
                r.interior.stress * 1e-6
            )),
            Ok(_) => {}
        }
        Some(result)
    }

    /// The worm FE model's largest deflection at the mesh point over the positions of `ltca`
    /// (MODEL §9.1), m; its compliance from the cache or computed once.
    fn worm_deflection(&mut self, geo: &Geometry, ltca: &Ltca) -> Result<f64, RunError> {
        let (compliance, warnings) =
            crate::bending::worm_deflection::mesh_point_compliance(self.gear, geo)
                .map_err(RunError::Bending)?;
        self.warnings.extend(warnings);
        Ok(ltca
            .positions
            .iter()
            .map(|p| compliance.lateral_deflection(&p.worm_force()))
            .fold(0.0, f64::max))
    }
}
