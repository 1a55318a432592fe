# concave remainder (paper 000 §3.2(2), §4.1(2), fig. 8-10, 13-14): a bicubic free-form surface with an
# R25 sphere on it; the virtual stylus at the tip P2 of the flat-type non-rotating tool touches both
# surfaces at once (|ΔR| ≤ 0.1 µm) and traces the concave boundary a ball end mill leaves. cl.csv
# carries both contacts, both normals and their bisector (the basic tool axis) for tool-attitude.
DEMOS += concave-remainder
FILTERS += stylus-trace
CONCAVE_REMAINDER := $(OUT)/concave-remainder
CONCAVE_REMAINDER_STYLUS ?= 1.0
CONCAVE_REMAINDER_CONTACT_TOL ?= 0.0001
CONCAVE_REMAINDER_CHORD_TOL ?= 0.001

.PHONY: demo-concave-remainder
demo-concave-remainder: $(CONCAVE_REMAINDER)/cl.csv

$(CONCAVE_REMAINDER)/model.json: data/stylus-trace/concave-remainder.json | $(CONCAVE_REMAINDER)/
	cp $< $@

$(CONCAVE_REMAINDER)/cl.csv $(CONCAVE_REMAINDER)/cl.svg $(CONCAVE_REMAINDER)/cl.json &: $(CONCAVE_REMAINDER)/model.json $(RELEASE)/stylus-trace
	$(RELEASE)/stylus-trace $< --mode two-surface --surfaces free-form,R25 -r $(CONCAVE_REMAINDER_STYLUS) \
	  --contact-tol $(CONCAVE_REMAINDER_CONTACT_TOL) --chord-tol $(CONCAVE_REMAINDER_CHORD_TOL) \
	  --svg $(CONCAVE_REMAINDER)/cl.svg --report $(CONCAVE_REMAINDER)/cl.json -o $(CONCAVE_REMAINDER)/cl.csv
