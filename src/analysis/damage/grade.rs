//! Grading an apple by its bruises against a standard's classes (docs/damage.md section 5): the
//! best class whose every limit its bruises meet, and why not the better ones.

use crate::scenario::damage::GradeClass;

/// The size of one bruise (`None` fields: the model gives no size, an onset model).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BruiseSize {
    /// Volume (mm^3).
    pub volume_mm3: Option<f64>,
    /// Surface diameter (mm).
    pub diameter_mm: Option<f64>,
    /// Depth (mm).
    pub depth_mm: Option<f64>,
    /// Surface area (mm^2).
    pub area_mm2: Option<f64>,
}

/// An apple's grade.
#[derive(Debug, Clone, PartialEq)]
pub struct Grade {
    /// The class's name, or the standard's name for apples below every class.
    pub grade: String,
    /// Its rank: 0 the best class, the number of classes for "below".
    pub rank: usize,
    /// Why not the best class (empty when the apple meets it).
    pub why: String,
}

/// The first limit of `c` that `bruises` break, in words; `None` when they meet every limit.
pub fn breaks(c: &GradeClass, bruises: &[BruiseSize]) -> Option<String> {
    let unknown = "a bruise of unknown size (the peak-force model gives onset only)";
    if let Some(n) = c.max_bruises {
        if bruises.len() > n as usize {
            return Some(match n {
                0 => format!("{} bruise(s) where {} allows none", bruises.len(), c.name),
                _ => format!("{} bruises, over {}'s {n}", bruises.len(), c.name),
            });
        }
    }
    type Get = fn(&BruiseSize) -> Option<f64>;
    let per: [(Option<f64>, Get, &str, &str); 4] = [
        (
            c.max_bruise_diameter_mm,
            |b| b.diameter_mm,
            "a bruise",
            "mm across",
        ),
        (c.max_bruise_depth_mm, |b| b.depth_mm, "a bruise", "mm deep"),
        (c.max_bruise_area_mm2, |b| b.area_mm2, "a bruise of", "mm^2"),
        (
            c.max_bruise_volume_mm3,
            |b| b.volume_mm3,
            "a bruise of",
            "mm^3",
        ),
    ];
    for (limit, get, what, unit) in per {
        let Some(limit) = limit else { continue };
        for b in bruises {
            match get(b) {
                None => return Some(format!("{unknown}, where {} limits its size", c.name)),
                Some(x) if x > limit => {
                    return Some(format!(
                        "{what} {} {unit}, over {}'s {} {unit}",
                        round(x),
                        c.name,
                        round(limit)
                    ))
                }
                _ => {}
            }
        }
    }
    type Total = fn(&BruiseSize) -> Option<f64>;
    let totals: [(Option<f64>, Total, &str); 2] = [
        (c.max_total_area_mm2, |b| b.area_mm2, "mm^2 bruised in all"),
        (
            c.max_total_volume_mm3,
            |b| b.volume_mm3,
            "mm^3 of bruise in all",
        ),
    ];
    for (limit, get, words) in totals {
        let Some(limit) = limit else { continue };
        let mut sum = 0.0;
        for b in bruises {
            match get(b) {
                None => return Some(format!("{unknown}, where {} limits the total", c.name)),
                Some(x) => sum += x,
            }
        }
        if sum > limit {
            return Some(format!(
                "{} {words}, over {}'s {}",
                round(sum),
                c.name,
                round(limit)
            ));
        }
    }
    None
}

/// Three significant digits, at least one decimal below 10.
fn round(x: f64) -> String {
    crate::math::human(x, 3, 1)
}

/// The grade of an apple with `bruises` by `classes` (best first); `below` for an apple that
/// meets none.
pub fn grade(classes: &[GradeClass], below: &str, bruises: &[BruiseSize]) -> Grade {
    let mut first_why = String::new();
    for (rank, c) in classes.iter().enumerate() {
        match breaks(c, bruises) {
            None => {
                return Grade {
                    grade: c.name.clone(),
                    rank,
                    why: first_why,
                }
            }
            Some(why) if rank == 0 => first_why = why,
            Some(_) => {}
        }
    }
    Grade {
        grade: below.to_string(),
        rank: classes.len(),
        why: first_why,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::damage::standard;

    fn bruise(d: f64, h: f64) -> BruiseSize {
        BruiseSize {
            volume_mm3: Some(super::super::geometry::cap_volume(d, h)),
            diameter_mm: Some(d),
            depth_mm: Some(h),
            area_mm2: Some(std::f64::consts::PI * d * d / 4.0),
        }
    }

    #[test]
    fn us_grades_by_washington_sizes() {
        let s = standard("usda-wa").unwrap();
        let g = |b: &[BruiseSize]| grade(&s.classes, s.below, b);
        assert_eq!(g(&[]).grade, "US Extra Fancy");
        assert_eq!(g(&[bruise(15.0, 3.0)]).grade, "US Extra Fancy");
        // 17 mm across: injury, not damage.
        let f = g(&[bruise(17.0, 3.0)]);
        assert_eq!((f.grade.as_str(), f.rank), ("US Fancy", 1));
        assert!(
            f.why.contains("17 mm across") && f.why.contains("15.9"),
            "{}",
            f.why
        );
        // 4 mm deep: injury (> 3.175 mm).
        assert_eq!(g(&[bruise(10.0, 4.0)]).grade, "US Fancy");
        // Two 12 mm bruises: 226 mm^2 together, over the 198 mm^2 of a 5/8 in disc.
        assert_eq!(g(&[bruise(12.0, 2.0), bruise(12.0, 2.0)]).grade, "US Fancy");
        assert_eq!(g(&[bruise(25.0, 3.0)]).grade, "US Utility");
        assert_eq!(g(&[bruise(30.0, 3.0)]).grade, "cull");
        assert_eq!(g(&[bruise(30.0, 3.0)]).rank, 3);
    }

    #[test]
    fn eu_extra_allows_no_bruise_and_unknown_sizes_fail_size_limits() {
        let s = standard("eu").unwrap();
        let g = |b: &[BruiseSize]| grade(&s.classes, s.below, b);
        assert_eq!(g(&[]).grade, "Extra");
        assert_eq!(g(&[bruise(5.0, 1.0)]).grade, "Class I");
        assert_eq!(g(&[bruise(13.0, 1.0)]).grade, "Class II");
        assert_eq!(g(&[bruise(15.0, 1.0)]).grade, "out of class");
        let onset = g(&[BruiseSize::default()]);
        assert_eq!(onset.grade, "out of class");
        assert!(onset.why.contains("allows none"), "{}", onset.why);
        let r = standard("research-500").unwrap();
        let unknown = grade(&r.classes, r.below, &[BruiseSize::default()]);
        assert!(unknown.why.contains("unknown size"), "{}", unknown.why);
    }
}
