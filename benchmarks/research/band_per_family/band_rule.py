"""Research implementation of RULE.md's variants (not the package): patches
``volerr.loop.drift.fit._leverage`` in the CLI's own process (``sitecustomize.py``).

``BAND_RULE=A``: the regularised fit's leverage with ``lam`` -> ``c lam`` (the Bayesian ridge
posterior under noise whose variance for the coefficients the autocorrelation inflates by
``c = (1 + rho)/(1 - rho)``, the prior's strength unchanged: Hoerl & Kennard 1970; Bishop
2006 3.3; Wilks 2011 5.2.4), ``rho`` from the regularised fit's own blocked-CV residuals
(:func:`volerr.loop.drift.interval.autocorrelation`, the interval's).  ``BAND_RULE=B``: the
same for the lag model's bank leverage, ``rho`` from the lag model's CV residuals.  The
interval then takes ``sigma^2 = 1 + c h`` as before (units: h dimensionless).
"""
import os

RULE = os.environ.get("BAND_RULE", "")


def install():
    from volerr.loop.drift import basis, family, fit
    from volerr.loop.drift import interval as band

    def _leverage(ch, fam, designs, reg, Z, cache):
        anchored = basis.whole_runs(ch.rule)
        if fam in ("regularised", "lag"):
            lam = reg["lambda_rel"] * float(ch.s.train.sum())
            if fam == "regularised" or RULE == "B":
                r = reg["cv_resid"] if fam == "regularised" else \
                    family.cv_residuals(ch, designs["lag"])
                rho = band.autocorrelation(r, ch.fold)
                lam = lam * (1.0 + rho) / (1.0 - rho)
            return band.shrink_leverage(cache, Z, reg["keep"], ch.s.run, ch.fold, anchored, lam)
        return band.cv_leverage(designs[fam][:, ch.n_runs:], ch.s.run, ch.fold, ch.s.train,
                                anchored)

    fit._leverage = _leverage
