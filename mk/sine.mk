# sine (paper 004): one period of the paper's sine profile → lines and arcs → NC and a plot.
# The paper's frame is 628 × 200 px for 62.8 mm × 20 mm, so the sine's amplitude is 10 mm.
DEMOS += sine
FILTERS += curve-fit-arcs
SINE := $(OUT)/sine
SINE_LENGTH ?= 62.8
SINE_AMPLITUDE ?= 10
SINE_STEP ?= 0.1
SINE_TOL ?= 0.01

.PHONY: demo-sine
demo-sine: $(SINE)/fitted.csv $(SINE)/paper.csv $(SINE)/fitted.nc

$(SINE)/points.csv: mk/sine.mk | $(SINE)/
	awk -v len=$(SINE_LENGTH) -v a=$(SINE_AMPLITUDE) -v step=$(SINE_STEP) 'BEGIN { \
	  print "# one period of y = a sin(2 pi x / len), sampled every step mm"; print "x,y"; \
	  n = int(len / step + 0.5); \
	  for (i = 0; i <= n; i++) { x = i * step; printf "%.4f,%.9f\n", x, a * sin(2 * 3.141592653589793 * x / len) } }' > $@

$(SINE)/fitted.csv $(SINE)/fitted.svg $(SINE)/fitted.json &: $(SINE)/points.csv $(RELEASE)/curve-fit-arcs
	$(RELEASE)/curve-fit-arcs $< --tol $(SINE_TOL) --svg $(SINE)/fitted.svg --report $(SINE)/fitted.json -o $(SINE)/fitted.csv

$(SINE)/paper.csv $(SINE)/paper.svg $(SINE)/paper.json &: $(SINE)/points.csv $(RELEASE)/curve-fit-arcs
	$(RELEASE)/curve-fit-arcs $< --method paper --curvature-threshold 0.01 --tol $(SINE_TOL) --svg $(SINE)/paper.svg --report $(SINE)/paper.json -o $(SINE)/paper.csv

$(SINE)/fitted.nc: $(SINE)/points.csv $(RELEASE)/curve-fit-arcs
	$(RELEASE)/curve-fit-arcs $< --to gcode --tol $(SINE_TOL) -o $@
