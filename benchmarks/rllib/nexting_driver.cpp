// RLLib's learners on a dumped nexting stream (benchmarks/rllib/README.md): TD(lambda) with a trace per demon
// (RLLib's TDLambda and ATrace, as its own NextingTest builds them), TD(lambda) with one trace per gamma (RLLib's
// vectors, the trace updated once a step per gamma), GTD(lambda) with a trace per demon (RLLib's GTDLambda).
//
// This file only #includes RLLib from the path given to the compiler (-I RLLIB/include); nothing of RLLib is
// copied here. Build and run:
//
//   g++ -O3 -march=native -DNDEBUG -std=c++11 -I RLLIB/include nexting_driver.cpp -o nexting_driver
//   nexting_driver STREAM MODE PREDICTIONS_OUT      (MODE: td | td-gamma | gtd | td-own-cut)
//
// STREAM (written by benchmarks/rllib/side_by_side.py's dump, little-endian):
//   int64[8]   steps N, active k, features n, sensors S, demons D, 0, 0, 0
//   float64[4] alpha (already divided by the active count), alpha_w (likewise), lambda, trace cut
//   int32[D] each demon's sensor, float64[D] its cumulant's scale, float64[D] its gamma
//   int32[(N+1) k] x_0 .. x_N's active indices, float64[(N+1) k] their values (value 0: padding)
//   float64[N S] the sensors at s_1 .. s_N
// The cumulant of demon d on step t is sensors[t][sensor[d]] * scale[d]; its continuation is gamma[d] (no
// episode ends inside the stream). Prints one line: mode, steps, wall s, CPU s, steps/s (wall and CPU); writes
// float64[D] each demon's prediction at s_N after the N steps.
//
// Trace cuts as Horde Lab's (entries of e below the cut set to 0 after each step): RLLib's TD trace holds
// alpha e, so its ATrace threshold is alpha * cut there; GTD's trace is e itself (threshold cut). Mode td-own-cut
// is td with ATrace's own default threshold, 1e-8 on alpha e: a cut 1 / alpha times Horde Lab's (shorter traces).

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>
#include <vector>

#include "PredictorAlgorithm.h"
#include "Trace.h"
#include "Vector.h"

using namespace RLLib;

struct Stream
{
    int64_t steps, k, n, sensors, demons;
    double alpha, alpha_w, lambda, cut;
    std::vector<int32_t> sensor;
    std::vector<double> scale, gamma;
    std::vector<SVector<double>*> x;  // [N + 1]
    std::vector<double> readings;     // [N S]
};

static void readExactly(FILE* f, void* out, size_t bytes)
{
    if (fread(out, 1, bytes, f) != bytes)
    {
        fprintf(stderr, "the stream file ends early\n");
        exit(2);
    }
}

static Stream load(const char* path)
{
    FILE* f = fopen(path, "rb");
    if (!f)
    {
        fprintf(stderr, "cannot open %s\n", path);
        exit(2);
    }
    Stream s;
    int64_t head[8];
    readExactly(f, head, sizeof head);
    s.steps = head[0], s.k = head[1], s.n = head[2], s.sensors = head[3], s.demons = head[4];
    double numbers[4];
    readExactly(f, numbers, sizeof numbers);
    s.alpha = numbers[0], s.alpha_w = numbers[1], s.lambda = numbers[2], s.cut = numbers[3];
    s.sensor.resize(s.demons), s.scale.resize(s.demons), s.gamma.resize(s.demons);
    readExactly(f, s.sensor.data(), 4 * s.demons);
    readExactly(f, s.scale.data(), 8 * s.demons);
    readExactly(f, s.gamma.data(), 8 * s.demons);
    std::vector<int32_t> index((s.steps + 1) * s.k);
    std::vector<double> value((s.steps + 1) * s.k);
    readExactly(f, index.data(), 4 * index.size());
    readExactly(f, value.data(), 8 * value.size());
    s.readings.resize(s.steps * s.sensors);
    readExactly(f, s.readings.data(), 8 * s.readings.size());
    fclose(f);
    for (int64_t t = 0; t <= s.steps; t++)
    {
        SVector<double>* v = new SVector<double>(s.n);
        for (int64_t j = 0; j < s.k; j++)
            if (value[t * s.k + j] != 0.0)
                v->setEntry(index[t * s.k + j], value[t * s.k + j]);
        s.x.push_back(v);
    }
    return s;
}

static double cpuSeconds()
{
    return double(clock()) / CLOCKS_PER_SEC;
}

int main(int argc, char** argv)
{
    if (argc != 4)
    {
        fprintf(stderr, "usage: %s STREAM td|td-gamma|gtd|td-own-cut PREDICTIONS_OUT\n", argv[0]);
        return 2;
    }
    const Stream s = load(argv[1]);
    const std::string mode = argv[2];
    const int D = int(s.demons);
    std::vector<double> prediction(D);
    std::vector<double> r(D);  // the cumulants of one step
    double wall = 0, cpu = 0;

    const bool ownCut = mode == "td-own-cut";
    const std::string learner = ownCut ? "td" : mode;
    if (learner == "td" || learner == "gtd")
    {
        // A trace per demon: RLLib's own classes, as NextingTest builds its demons.
        std::vector<Trace<double>*> traces;
        std::vector<TDLambda<double>*> td;
        std::vector<GTDLambda<double>*> gtd;
        for (int d = 0; d < D; d++)
        {
            if (learner == "td")
            {
                traces.push_back(ownCut ? new ATrace<double>(int(s.n)) : new ATrace<double>(int(s.n), s.alpha * s.cut));
                td.push_back(new TDLambda<double>(s.alpha, s.gamma[d], s.lambda, traces.back()));
                td.back()->initialize();
            }
            else
            {
                traces.push_back(new ATrace<double>(int(s.n), s.cut));
                gtd.push_back(new GTDLambda<double>(s.alpha, s.alpha_w, s.gamma[d], s.lambda, traces.back()));
                static_cast<OnPolicyTD<double>*>(gtd.back())->initialize();  // public through the interface
            }
        }
        auto began = std::chrono::steady_clock::now();
        double cpuBegan = cpuSeconds();
        for (int64_t t = 0; t < s.steps; t++)
        {
            const double* sensors = &s.readings[t * s.sensors];
            for (int d = 0; d < D; d++)
            {
                const double reward = sensors[s.sensor[d]] * s.scale[d];
                if (learner == "td")
                    td[d]->update(s.x[t], s.x[t + 1], reward, s.gamma[d]);
                else
                    gtd[d]->update(s.x[t], s.x[t + 1], s.gamma[d], s.lambda, 1.0, reward, 0.0);
            }
        }
        wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
        cpu = cpuSeconds() - cpuBegan;
        for (int d = 0; d < D; d++)
            prediction[d] = learner == "td" ? td[d]->predict(s.x[s.steps])
                                         : static_cast<OnPolicyTD<double>*>(gtd[d])->predict(s.x[s.steps]);
    }
    else if (mode == "td-gamma")
    {
        // One trace per gamma, shared by the demons of that gamma (as Horde Lab shares it): each step the
        // trace of a gamma moves once, e = gamma_t lambda e + x_t (cut), then every demon of it
        // does v += alpha delta e. RLLib's vectors do the work; its TDLambda class updates a trace of its own.
        std::vector<double> gammas;
        std::vector<int> group(D);
        for (int d = 0; d < D; d++)
        {
            int g = 0;
            while (g < int(gammas.size()) && gammas[g] != s.gamma[d])
                g++;
            if (g == int(gammas.size()))
                gammas.push_back(s.gamma[d]);
            group[d] = g;
        }
        std::vector<ATrace<double>*> traces;
        for (size_t g = 0; g < gammas.size(); g++)
            traces.push_back(new ATrace<double>(int(s.n), s.cut));
        std::vector<PVector<double>*> v;
        for (int d = 0; d < D; d++)
            v.push_back(new PVector<double>(int(s.n)));
        auto began = std::chrono::steady_clock::now();
        double cpuBegan = cpuSeconds();
        for (int64_t t = 0; t < s.steps; t++)
        {
            const double* sensors = &s.readings[t * s.sensors];
            for (size_t g = 0; g < gammas.size(); g++)
                traces[g]->update(gammas[g] * s.lambda, s.x[t]);  // gamma_t: continuation 1, no episode ends
            for (int d = 0; d < D; d++)
            {
                const double reward = sensors[s.sensor[d]] * s.scale[d];
                const double delta = reward + s.gamma[d] * v[d]->dot(s.x[t + 1]) - v[d]->dot(s.x[t]);
                v[d]->addToSelf(s.alpha * delta, traces[group[d]]->vect());
            }
        }
        wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
        cpu = cpuSeconds() - cpuBegan;
        for (int d = 0; d < D; d++)
            prediction[d] = v[d]->dot(s.x[s.steps]);
    }
    else
    {
        fprintf(stderr, "unknown mode %s (td, td-gamma, gtd or td-own-cut)\n", mode.c_str());
        return 2;
    }

    FILE* out = fopen(argv[3], "wb");
    if (!out || fwrite(prediction.data(), 8, D, out) != size_t(D))
    {
        fprintf(stderr, "cannot write %s\n", argv[3]);
        return 2;
    }
    fclose(out);
    printf("%s steps %lld wall %.6f cpu %.6f steps_per_s_wall %.4f steps_per_s_cpu %.4f demons %d\n", mode.c_str(),
           (long long)s.steps, wall, cpu, s.steps / wall, s.steps / cpu, D);
    return 0;
}
