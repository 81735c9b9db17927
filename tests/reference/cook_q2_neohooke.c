/* Independent check: Q2 plane-strain FE for Cook's membrane with Psi = mu/2 (I1bar - 3) + kappa/4 (J^2 - 1 - 2 ln J),
 * P by central differences of W, A by central differences of P; dense Newton. */
#include <lapacke.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
static const double V[4][2]={{0,0},{48,44},{48,60},{0,44}};
static double MU=0.4225, KAPPA;
static void map(double s,double t,double*x){ for(int d=0;d<2;d++) x[d]=(1-s)*(1-t)*V[0][d]+s*(1-t)*V[1][d]+s*t*V[2][d]+(1-s)*t*V[3][d]; }
static void q1d(double r,double*N,double*dN){ N[0]=0.5*r*(r-1); N[1]=1-r*r; N[2]=0.5*r*(r+1); dN[0]=r-0.5; dN[1]=-2*r; dN[2]=r+0.5; }
static double W(const double*F){ double J=F[0]*F[3]-F[1]*F[2]; double I1=F[0]*F[0]+F[1]*F[1]+F[2]*F[2]+F[3]*F[3]+1; return MU/2*(pow(J,-2.0/3)*I1-3)+KAPPA/4*(J*J-1-2*log(J)); }
static void Pfd(const double*F,double*P){ double h=1e-6; for(int i=0;i<4;i++){ double Fp[4],Fm[4]; memcpy(Fp,F,32); memcpy(Fm,F,32); Fp[i]+=h; Fm[i]-=h; P[i]=(W(Fp)-W(Fm))/(2*h);} }
static void Afd(const double*F,double*A){ double h=1e-5; for(int j=0;j<4;j++){ double Fp[4],Fm[4],Pp[4],Pm[4]; memcpy(Fp,F,32); memcpy(Fm,F,32); Fp[j]+=h; Fm[j]-=h; Pfd(Fp,Pp); Pfd(Fm,Pm); for(int i=0;i<4;i++) A[i*4+j]=(Pp[i]-Pm[i])/(2*h);} }
int main(int argc,char**argv){
  int ne=atoi(argv[1]), nsteps=10; int nn=2*ne+1, ndof=2*nn*nn; double nu=0.3; KAPPA=2*MU*(1+nu)/(3*(1-2*nu));
  double *X=malloc(sizeof(double)*nn*nn*2), *u=calloc(ndof,8), *R=malloc(8*ndof), *K=malloc((size_t)8*ndof*ndof), *fext=calloc(ndof,8);
  for(int j=0;j<nn;j++)for(int i=0;i<nn;i++) map((double)i/(nn-1),(double)j/(nn-1),X+2*(j*nn+i));
  double g[3]={-sqrt(0.6),0,sqrt(0.6)}, gw[3]={5.0/9,8.0/9,5.0/9};
  for(int ey=0;ey<ne;ey++) for(int q=0;q<3;q++){ double N[3],d[3]; q1d(g[q],N,d); for(int b=0;b<3;b++){ int node=(2*ey+b)*nn+(nn-1); fext[2*node+1]+=gw[q]*(16.0/ne)/2*N[b]/16.0; } }
  lapack_int *ipiv=malloc(sizeof(lapack_int)*ndof);
  for(int step=1;step<=nsteps;step++){ double t=(double)step/nsteps;
    for(int it=0;it<30;it++){
      memset(R,0,8*ndof); memset(K,0,(size_t)8*ndof*ndof);
      for(int ey=0;ey<ne;ey++)for(int ex=0;ex<ne;ex++){ int nodes[9]; for(int b=0;b<3;b++)for(int a=0;a<3;a++) nodes[b*3+a]=(2*ey+b)*nn+(2*ex+a);
        for(int qy=0;qy<3;qy++)for(int qx=0;qx<3;qx++){ double Nx[3],dNx[3],Ny[3],dNy[3]; q1d(g[qx],Nx,dNx); q1d(g[qy],Ny,dNy);
          double dNr[9][2]; for(int b=0;b<3;b++)for(int a=0;a<3;a++){dNr[b*3+a][0]=dNx[a]*Ny[b]; dNr[b*3+a][1]=Nx[a]*dNy[b];}
          double J[2][2]={{0,0},{0,0}}; for(int k=0;k<9;k++)for(int d=0;d<2;d++)for(int r=0;r<2;r++) J[d][r]+=X[2*nodes[k]+d]*dNr[k][r];
          double det=J[0][0]*J[1][1]-J[0][1]*J[1][0]; double Ji[2][2]={{J[1][1]/det,-J[0][1]/det},{-J[1][0]/det,J[0][0]/det}};
          double dN[9][2]; for(int k=0;k<9;k++)for(int d=0;d<2;d++) dN[k][d]=dNr[k][0]*Ji[0][d]+dNr[k][1]*Ji[1][d];
          double w=gw[qx]*gw[qy]*fabs(det), F[4]={1,0,0,1}, P[4], A[16];
          for(int k=0;k<9;k++)for(int a=0;a<2;a++)for(int Jd=0;Jd<2;Jd++) F[a*2+Jd]+=u[2*nodes[k]+a]*dN[k][Jd];
          Pfd(F,P); Afd(F,A);
          for(int k=0;k<9;k++)for(int a=0;a<2;a++){ double s=0; for(int Jd=0;Jd<2;Jd++) s+=P[a*2+Jd]*dN[k][Jd]; R[2*nodes[k]+a]+=w*s;
            for(int l=0;l<9;l++)for(int b=0;b<2;b++){ double v=0; for(int Jd=0;Jd<2;Jd++)for(int L=0;L<2;L++) v+=dN[k][Jd]*A[(a*2+Jd)*4+b*2+L]*dN[l][L]; K[(size_t)(2*nodes[k]+a)*ndof+2*nodes[l]+b]+=w*v; } } } }
      for(int i=0;i<ndof;i++) R[i]-=t*fext[i];
      for(int j=0;j<nn;j++){ int node=j*nn; for(int c=0;c<2;c++){ int r=2*node+c; for(int k=0;k<ndof;k++){K[(size_t)r*ndof+k]=0;K[(size_t)k*ndof+r]=0;} K[(size_t)r*ndof+r]=1; R[r]=0; } }
      double rn=0; for(int i=0;i<ndof;i++) rn+=R[i]*R[i]; rn=sqrt(rn); if(rn<1e-9) break;
      for(int i=0;i<ndof;i++) R[i]=-R[i]; LAPACKE_dgesv(LAPACK_ROW_MAJOR,ndof,1,K,ndof,ipiv,R,1); for(int i=0;i<ndof;i++) u[i]+=R[i]; } }
  int tip=(nn-1)*nn+(nn-1); printf("ne=%d NH tip uy=%.5f\n",ne,u[2*tip+1]); return 0; }
