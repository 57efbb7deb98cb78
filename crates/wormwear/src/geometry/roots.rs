//! Small, robust 1-D solvers (bisection, Illinois false position, Brent maximisation).

/// Root of `f` in [a, b] by bisection (f(a), f(b) of opposite signs), to absolute `tol` in x.
/// Returns None when the bracket is invalid or `f` gives NaN.
pub fn bisect(f: impl Fn(f64) -> f64, a: f64, b: f64, tol: f64) -> Option<f64> {
    let (mut lo, mut hi) = (a, b);
    let mut flo = f(lo);
    let fhi = f(hi);
    if flo.is_nan() || fhi.is_nan() || flo * fhi > 0.0 {
        return None;
    }
    if flo == 0.0 {
        return Some(lo);
    }
    if fhi == 0.0 {
        return Some(hi);
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if (hi - lo).abs() <= tol || mid == lo || mid == hi {
            return Some(mid);
        }
        let fm = f(mid);
        if fm.is_nan() {
            return None;
        }
        if fm == 0.0 {
            return Some(mid);
        }
        if (fm < 0.0) == (flo < 0.0) {
            lo = mid;
            flo = fm;
        } else {
            hi = mid;
        }
    }
    Some(0.5 * (lo + hi))
}

/// Root of `f` between a and b (their values fa, fb given, of opposite signs) by the Illinois
/// false position: the secant point replaces the end of its sign, and the other end's value is
/// halved when the same end is replaced twice in a row. Stops at the point c where `done(c,
/// f(c), the bracket's width)`, else after `iterations` at the bracket's middle; an error of `f`
/// is passed on.
pub fn illinois<E>(
    mut f: impl FnMut(f64) -> Result<f64, E>,
    (mut a, mut fa): (f64, f64),
    (mut b, mut fb): (f64, f64),
    done: impl Fn(f64, f64, f64) -> bool,
    iterations: usize,
) -> Result<f64, E> {
    let mut side = 0i8;
    for _ in 0..iterations {
        let c = (a * fb - b * fa) / (fb - fa);
        let fc = f(c)?;
        if done(c, fc, (b - a).abs()) {
            return Ok(c);
        }
        if (fc < 0.0) == (fa < 0.0) {
            (a, fa) = (c, fc);
            if side == -1 {
                fb *= 0.5;
            }
            side = -1;
        } else {
            (b, fb) = (c, fc);
            if side == 1 {
                fa *= 0.5;
            }
            side = 1;
        }
    }
    Ok(0.5 * (a + b))
}

/// Maximum of `f` on [a, b] by Brent's method (golden section with parabolic steps), to
/// absolute tolerance `tol` in x. Returns (x, f(x)).
pub fn brent_max(f: impl Fn(f64) -> f64, a: f64, b: f64, tol: f64) -> (f64, f64) {
    let g = |x: f64| -f(x);
    const CGOLD: f64 = 0.381_966_011_250_105;
    let (mut a, mut b) = (a.min(b), a.max(b));
    let mut x = a + CGOLD * (b - a);
    let (mut w, mut v) = (x, x);
    let mut fx = g(x);
    let (mut fw, mut fv) = (fx, fx);
    let mut d: f64 = 0.0;
    let mut e: f64 = 0.0;
    for _ in 0..200 {
        let xm = 0.5 * (a + b);
        let tol1 = tol + 1e-12 * x.abs();
        let tol2 = 2.0 * tol1;
        if (x - xm).abs() <= tol2 - 0.5 * (b - a) {
            break;
        }
        let mut golden = true;
        if e.abs() > tol1 {
            // Parabola through x, w, v.
            let r = (x - w) * (fx - fv);
            let mut q = (x - v) * (fx - fw);
            let mut p = (x - v) * q - (x - w) * r;
            q = 2.0 * (q - r);
            if q > 0.0 {
                p = -p;
            }
            q = q.abs();
            let etemp = e;
            if p.abs() < (0.5 * q * etemp).abs() && p > q * (a - x) && p < q * (b - x) {
                e = d;
                d = p / q;
                let u = x + d;
                if u - a < tol2 || b - u < tol2 {
                    d = if xm >= x { tol1 } else { -tol1 };
                }
                golden = false;
            }
        }
        if golden {
            e = if x >= xm { a - x } else { b - x };
            d = CGOLD * e;
        }
        let u = if d.abs() >= tol1 {
            x + d
        } else {
            x + tol1.copysign(d)
        };
        let fu = g(u);
        if fu <= fx {
            if u >= x {
                a = x;
            } else {
                b = x;
            }
            v = w;
            fv = fw;
            w = x;
            fw = fx;
            x = u;
            fx = fu;
        } else {
            if u < x {
                a = u;
            } else {
                b = u;
            }
            if fu <= fw || w == x {
                v = w;
                fv = fw;
                w = u;
                fw = fu;
            } else if fu <= fv || v == x || v == w {
                v = u;
                fv = fu;
            }
        }
    }
    (x, -fx)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn illinois_finds_the_cube_root_from_either_sign_and_passes_errors_on() {
        let exact = 2f64.cbrt();
        let done = |_: f64, y: f64, width: f64| y == 0.0 || width < 1e-14;
        for sign in [1.0, -1.0] {
            let f = |x: f64| Ok::<f64, ()>(sign * (x * x * x - 2.0));
            let r = illinois(f, (0.0, -2.0 * sign), (2.0, 6.0 * sign), done, 100).unwrap();
            assert!((r - exact).abs() < 1e-12, "{r}");
        }
        let failing = |x: f64| if x > 0.5 { Err("no") } else { Ok(x - 1.0) };
        assert_eq!(
            illinois(failing, (0.0, -1.0), (2.0, 1.0), done, 100),
            Err("no")
        );
    }

    #[test]
    fn bisect_finds_cube_root() {
        let r = bisect(|x| x * x * x - 2.0, 0.0, 2.0, 1e-14).unwrap();
        assert!((r - 2f64.cbrt()).abs() < 1e-13);
        assert!(bisect(|x| x * x + 1.0, -1.0, 1.0, 1e-12).is_none());
    }

    #[test]
    fn brent_finds_interior_and_boundary_maxima() {
        let (x, fx) = brent_max(|x| -(x - 0.3).powi(2) + 1.0, -1.0, 2.0, 1e-12);
        assert!((x - 0.3).abs() < 1e-9 && (fx - 1.0).abs() < 1e-15);
        let (x, _) = brent_max(|x| (3.0 * x).sin(), 0.0, 1.0, 1e-12);
        assert!((x - std::f64::consts::PI / 6.0).abs() < 1e-8);
        // Monotone function: converges to the bound.
        let (x, _) = brent_max(|x| x, 0.0, 1.0, 1e-12);
        assert!(x > 1.0 - 1e-9);
    }
}
