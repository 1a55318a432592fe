# sine (paper 004): one period of the paper's sine profile → lines and arcs → NC and a plot, then
# (paper 004 §4, fig. 6) the tip paths of a square and a ball end mill of radius 1.5 mm cutting
# it from above → plots, with the gouge regions of the unoffset square end mill → NC for a 3-axis
# machine (post-6axis with the job's setup: the arcs stay G2/G3 in G18, every move checked against
# the profile as a solid, scripts/profile-stl.py).
# The paper's frame is 628 × 200 px for 62.8 mm × 20 mm, so the sine's amplitude is 10 mm.
DEMOS += sine
FILTERS += curve-fit-arcs offset post-6axis
SINE := $(OUT)/sine
SINE_LENGTH ?= 62.8
SINE_AMPLITUDE ?= 10
SINE_STEP ?= 0.1
SINE_TOL ?= 0.01
SINE_TOOL_RADIUS ?= 1.5
SINE_TOOLS := square ball
SINE_MACHINE ?= data/post-6axis/three-axis.json

.PHONY: demo-sine
demo-sine: $(SINE)/fitted.csv $(SINE)/paper.csv \
  $(foreach t,$(SINE_TOOLS),$(SINE)/tip-$(t).csv $(SINE)/$(t).ngc)

$(SINE)/points.csv: mk/sine.mk | $(SINE)/
	awk -v len=$(SINE_LENGTH) -v a=$(SINE_AMPLITUDE) -v step=$(SINE_STEP) 'BEGIN { \
	  print "# one period of y = a sin(2 pi x / len), sampled every step mm"; print "x,y"; \
	  n = int(len / step + 0.5); \
	  for (i = 0; i <= n; i++) { x = i * step; printf "%.4f,%.9f\n", x, a * sin(2 * 3.141592653589793 * x / len) } }' > $@

$(SINE)/fitted.csv $(SINE)/fitted.svg $(SINE)/fitted.json &: $(SINE)/points.csv $(RELEASE)/curve-fit-arcs
	$(RELEASE)/curve-fit-arcs $< --tol $(SINE_TOL) --svg $(SINE)/fitted.svg --report $(SINE)/fitted.json -o $(SINE)/fitted.csv

$(SINE)/paper.csv $(SINE)/paper.svg $(SINE)/paper.json &: $(SINE)/points.csv $(RELEASE)/curve-fit-arcs
	$(RELEASE)/curve-fit-arcs $< --method paper --curvature-threshold 0.01 --tol $(SINE_TOL) --svg $(SINE)/paper.svg --report $(SINE)/paper.json -o $(SINE)/paper.csv

# The fitted profile stood up in the xz plane (the tool along +z, as a 3-axis mill cuts it): y → z.
# Arcs seen from +y turn the other way round (G18), so cw and ccw swap.
$(SINE)/profile-xz.csv: $(SINE)/fitted.csv
	awk -F, 'NR == 1 { print "path,move,x,y,z,xc,zc,plane"; next } \
	  { m = $$1; arc = (m == "cw" || m == "ccw"); if (m == "cw") m = "ccw"; else if (m == "ccw") m = "cw"; \
	    print "0," m "," $$2 ",0," $$3 "," $$4 "," $$5 "," (arc ? "xz" : "") }' $< > $@

# Tip paths: ball = normal offset by R lowered by R; square = flat bottom lowered onto the profile.
# The plot shows the profile, the tool on the tip path and the gouges of the unoffset square end mill.
$(SINE)/tip-%.csv $(SINE)/tip-%.svg $(SINE)/tip-%.json &: $(SINE)/profile-xz.csv $(RELEASE)/offset
	$(RELEASE)/offset $< --profile $* --up z --radius $(SINE_TOOL_RADIUS) \
	  --svg $(SINE)/tip-$*.svg --report $(SINE)/tip-$*.json -o $(SINE)/tip-$*.csv

# The profile as a solid (material under it, 5 mm either side of y = 0) for the collision check;
# the jobs' setups and tools beside it, which they name.
$(SINE)/profile.stl: $(SINE)/profile-xz.csv scripts/profile-stl.py
	python3 scripts/profile-stl.py $< $@ --width 5 --bottom -20

$(SINE)/setup-%.json: data/jobs/sine-%.json | $(SINE)/
	cp $< $@

$(SINE)/flat-d3.json $(SINE)/ball-d3.json: $(SINE)/%.json: data/jobs/%.json | $(SINE)/
	cp $< $@

$(SINE)/%.ngc $(SINE)/%.json &: $(SINE)/tip-%.csv $(SINE)/setup-%.json $(SINE)/profile.stl $(SINE)/flat-d3.json $(SINE)/ball-d3.json $(SINE_MACHINE) $(RELEASE)/post-6axis
	$(RELEASE)/post-6axis $< --machine $(SINE_MACHINE) --setup $(SINE)/setup-$*.json --report $(SINE)/$*.json -o $(SINE)/$*.ngc
