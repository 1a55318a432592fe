# roughness (paper 003): the surface a ball end mill leaves, recomputed. Fig. 2 (r 5 mm, pick
# feed 0.5 mm, 2 flutes, 0.5 mm per tooth) at tilts 0°, 3° and 10°; the flat tip of eq. 6-7 and
# the surface it leaves; fig. 4b (roughness against feed per tooth for r 5, 10, 15 mm), fig. 5b
# (against tilt 0-15°), §3.2 (against spindle speed at constant feed); a raster program's
# z-map. The reconstructed fig. 2 conditions (lean, pass phase) are argued in docs/rough-sim.md.
DEMOS += roughness
FILTERS += rough-sim post-6axis
ROUGHNESS := $(OUT)/roughness
ROUGHNESS_TOOL ?= data/rough-sim/ball-r5-z2.json
ROUGHNESS_PICK ?= 0.5
ROUGHNESS_FZ ?= 0.5
ROUGHNESS_LEAN ?= minus-x
ROUGHNESS_PHASE ?= 90
ROUGHNESS_STEP ?= 0.002
ROUGHNESS_SWEEP_STEP ?= 0.004
ROUGHNESS_FLAT ?= 0.5
ROUGHNESS_FLAT_SHORT ?= 0.3
ROUGHNESS_FEED ?= 2000
ROUGHNESS_MACHINE ?= data/post-6axis/three-axis.json
ROUGHNESS_SETUP ?= data/jobs/roughness-raster.json
ROUGHNESS_COND = --pick $(ROUGHNESS_PICK) --lean $(ROUGHNESS_LEAN) --pass-phase $(ROUGHNESS_PHASE)

.PHONY: demo-roughness
demo-roughness: $(foreach t,0 3 10,$(ROUGHNESS)/fig2-tilt$(t).csv) $(ROUGHNESS)/flat-tip.csv $(ROUGHNESS)/fig7-flat.csv $(ROUGHNESS)/fig7-flat-short.csv \
  $(ROUGHNESS)/fig4b-feed.csv $(ROUGHNESS)/fig5b-tilt.csv $(ROUGHNESS)/spindle.csv $(ROUGHNESS)/raster-zmap.csv $(ROUGHNESS)/raster.ngc

# Fig. 2 / fig. 5a: one periodic cell (pick feed × feed per tooth), heights, colour map, the
# profiles through the highest point, the figures (cusp, remainder, Rz/Ra, up- and down-cut).
$(ROUGHNESS)/fig2-tilt%.csv $(ROUGHNESS)/fig2-tilt%.svg $(ROUGHNESS)/fig2-tilt%.json $(ROUGHNESS)/fig2-tilt%.profiles.csv: $(ROUGHNESS_TOOL) $(RELEASE)/rough-sim | $(ROUGHNESS)/
	$(RELEASE)/rough-sim patch $< $(ROUGHNESS_COND) --feed-per-tooth $(ROUGHNESS_FZ) --tilt $* --step $(ROUGHNESS_STEP) \
	  --svg $(ROUGHNESS)/fig2-tilt$*.svg --profiles $(ROUGHNESS)/fig2-tilt$*.profiles.csv --report $(ROUGHNESS)/fig2-tilt$*.json -o $(ROUGHNESS)/fig2-tilt$*.csv

# Eq. 6-7: r_M, r_N, r0, δ, and the smallest flat the simulation itself needs.
$(ROUGHNESS)/flat-tip.csv $(ROUGHNESS)/flat-tip.json &: $(ROUGHNESS_TOOL) $(RELEASE)/rough-sim | $(ROUGHNESS)/
	$(RELEASE)/rough-sim flat-tip $< $(ROUGHNESS_COND) --feed-per-tooth $(ROUGHNESS_FZ) --simulate --step $(ROUGHNESS_SWEEP_STEP) \
	  --report $(ROUGHNESS)/flat-tip.json -o $(ROUGHNESS)/flat-tip.csv

# Fig. 7: the fig. 2 cell cut by the tool with eq. 7's flat: the remainder is gone.
$(ROUGHNESS)/fig7-flat.csv $(ROUGHNESS)/fig7-flat.svg $(ROUGHNESS)/fig7-flat.json &: $(ROUGHNESS_TOOL) $(RELEASE)/rough-sim | $(ROUGHNESS)/
	$(RELEASE)/rough-sim patch $< $(ROUGHNESS_COND) --feed-per-tooth $(ROUGHNESS_FZ) --flat-radius $(ROUGHNESS_FLAT) --step $(ROUGHNESS_STEP) \
	  --svg $(ROUGHNESS)/fig7-flat.svg --report $(ROUGHNESS)/fig7-flat.json -o $(ROUGHNESS)/fig7-flat.csv

# Fig. 7(b): a flat shorter than eq. 7's (r' < r0) leaves part of the remainder.
$(ROUGHNESS)/fig7-flat-short.csv $(ROUGHNESS)/fig7-flat-short.svg $(ROUGHNESS)/fig7-flat-short.json &: $(ROUGHNESS_TOOL) $(RELEASE)/rough-sim | $(ROUGHNESS)/
	$(RELEASE)/rough-sim patch $< $(ROUGHNESS_COND) --feed-per-tooth $(ROUGHNESS_FZ) --flat-radius $(ROUGHNESS_FLAT_SHORT) --step $(ROUGHNESS_STEP) \
	  --svg $(ROUGHNESS)/fig7-flat-short.svg --report $(ROUGHNESS)/fig7-flat-short.json -o $(ROUGHNESS)/fig7-flat-short.csv

# Fig. 4b: roughness against feed per tooth, r = 5, 10, 15 mm.
$(ROUGHNESS)/fig4b-feed.csv $(ROUGHNESS)/fig4b-feed.svg &: $(ROUGHNESS_TOOL) $(RELEASE)/rough-sim | $(ROUGHNESS)/
	$(RELEASE)/rough-sim sweep $< $(ROUGHNESS_COND) --feed-per-tooth $(ROUGHNESS_FZ) --vary feed-per-tooth \
	  --values 0.01,0.05,0.1,0.15,0.2,0.25,0.3,0.35,0.4,0.45,0.5,0.55,0.6 --radii 5,10,15 --step $(ROUGHNESS_SWEEP_STEP) \
	  --svg $(ROUGHNESS)/fig4b-feed.svg -o $(ROUGHNESS)/fig4b-feed.csv

# Fig. 5b: roughness against tilt 0-15°, r = 5, 10, 15 mm.
$(ROUGHNESS)/fig5b-tilt.csv $(ROUGHNESS)/fig5b-tilt.svg &: $(ROUGHNESS_TOOL) $(RELEASE)/rough-sim | $(ROUGHNESS)/
	$(RELEASE)/rough-sim sweep $< $(ROUGHNESS_COND) --feed-per-tooth $(ROUGHNESS_FZ) --vary tilt \
	  --values 0,1,2,3,4,5,6,7,8,9,10,11,12,13,14,15 --radii 5,10,15 --step $(ROUGHNESS_SWEEP_STEP) \
	  --svg $(ROUGHNESS)/fig5b-tilt.svg -o $(ROUGHNESS)/fig5b-tilt.csv

# §3.2: the remainder against spindle speed at a constant feed F.
$(ROUGHNESS)/spindle.csv $(ROUGHNESS)/spindle.svg &: $(ROUGHNESS_TOOL) $(RELEASE)/rough-sim | $(ROUGHNESS)/
	$(RELEASE)/rough-sim sweep $< $(ROUGHNESS_COND) --feed $(ROUGHNESS_FEED) --spindle 2000 --vary spindle \
	  --values 1000,1500,2000,2500,3000,4000,5000,6000,8000,10000 --step $(ROUGHNESS_SWEEP_STEP) \
	  --svg $(ROUGHNESS)/spindle.svg -o $(ROUGHNESS)/spindle.csv

# Beyond the paper: a raster program (five passes along +y, 0.5 mm apart, 1000 mm/min) as a
# toolpath table, simulated on a z-map at 1000 rpm with the same edge kinematics.
$(ROUGHNESS)/raster.csv: mk/roughness.mk | $(ROUGHNESS)/
	awk 'BEGIN { print "path,move,x,y,z,f"; \
	  for (p = 0; p < 5; p++) { x = -1 + 0.5 * p; printf "%d,line,%.3f,-6,0,1000\n%d,line,%.3f,6,0,1000\n", p, x, p, x } }' > $@

$(ROUGHNESS)/raster-zmap.csv $(ROUGHNESS)/raster-zmap.svg $(ROUGHNESS)/raster-zmap.json &: $(ROUGHNESS)/raster.csv $(ROUGHNESS_TOOL) $(RELEASE)/rough-sim
	$(RELEASE)/rough-sim zmap $< --tool $(ROUGHNESS_TOOL) --spindle 1000 --step 0.01 --region=-0.75,0.75,-0.5,0.5 \
	  --svg $(ROUGHNESS)/raster-zmap.svg --report $(ROUGHNESS)/raster-zmap.json -o $(ROUGHNESS)/raster-zmap.csv

# The raster as the program a 3-axis machine runs: linked through the safe height, checked.
$(ROUGHNESS)/raster.ngc $(ROUGHNESS)/raster.json &: $(ROUGHNESS)/raster.csv $(ROUGHNESS_MACHINE) $(ROUGHNESS_SETUP) $(RELEASE)/post-6axis
	$(RELEASE)/post-6axis $< --machine $(ROUGHNESS_MACHINE) --setup $(ROUGHNESS_SETUP) --report $(ROUGHNESS)/raster.json -o $(ROUGHNESS)/raster.ngc
