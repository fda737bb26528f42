"""One router per resource: health, maps, days, orders, site, plan, jobs, fleet."""
