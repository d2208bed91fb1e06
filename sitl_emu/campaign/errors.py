"""The campaign's user errors: each str(err) is one sentence the command line prints as it is."""

from __future__ import annotations


class CampaignError(Exception):
    """A campaign that cannot start: a missing scenario, a bad case file, an output of other cases."""


class CaseError(CampaignError, ValueError):
    """A case definition written wrongly (a key, a distribution, a parameter, a fault)."""
