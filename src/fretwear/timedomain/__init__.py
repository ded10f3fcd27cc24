"""The time-domain reference: integration with exact contact and Coulomb friction, steady
states and their classification, quasi-static incremental wear, the stability check of a
periodic solution, the time-averaged wear rate, and the fallback the drivers of the harmonic
balance and wear may be handed (:mod:`fretwear.timedomain.fallback`)."""
